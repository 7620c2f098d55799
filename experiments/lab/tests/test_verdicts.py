"""``lab.verdicts``: the results page's one labelling rule, and the page holding its table verbatim."""

from __future__ import annotations

from pathlib import Path

import pytest

from lab.verdicts import (
    CELLS,
    INCONCLUSIVE,
    NOT_REPRODUCED,
    NOT_TESTABLE,
    REPRODUCED,
    REVERSED,
    Cell,
    Evidence,
    cell_label,
    correlation_interval,
    interval_label,
    posthoc,
    table_markdown,
)

RESULTS_PAGE = Path(__file__).resolve().parents[3] / "docs" / "results.md"


@pytest.mark.parametrize(
    ("low", "high", "label"),
    [
        (0.001, 0.05, REPRODUCED),
        (-0.03, -0.001, REVERSED),
        (-0.008, 0.029, NOT_REPRODUCED),  # MT10 pixels need - uniform
        (-0.004, 0.032, NOT_REPRODUCED),  # past the plateau need - uniform: the same reading
        (-0.035, 0.05, INCONCLUSIVE),  # reaches the margin
        (-0.43, 0.31, INCONCLUSIVE),  # a hardest-task interval
    ],
)
def test_a_success_interval_gets_the_label_its_ends_give(low, high, label):
    assert interval_label(Evidence(0.0, low, high)) == label


def test_a_post_hoc_interval_never_says_reproduced_or_reversed():
    assert interval_label(posthoc(0.018, 0.0001, 0.035)) == INCONCLUSIVE
    assert interval_label(posthoc(-0.051, -0.071, -0.031)) == NOT_REPRODUCED
    assert interval_label(posthoc(0.006, -0.003, 0.016)) == NOT_REPRODUCED


def test_an_unfair_protocol_can_only_show_the_claim_absent():
    assert interval_label(Evidence(0.1, 0.05, 0.15), fair=False) == INCONCLUSIVE
    assert interval_label(Evidence(-0.1, -0.15, -0.05), fair=False) == INCONCLUSIVE
    assert interval_label(Evidence(0.0, -0.01, 0.01), fair=False) == NOT_REPRODUCED


def test_demos_are_a_saving_when_negative_with_a_margin_of_a_fifth_of_the_baseline():
    def demos(low, high):
        return Evidence(0.0, low, high, kind="demos", baseline_demos=20.0)

    assert interval_label(demos(-9.0, -1.0)) == REPRODUCED
    assert interval_label(demos(-3.9, 2.0)) == NOT_REPRODUCED
    assert interval_label(demos(-9.7, 9.2)) == INCONCLUSIVE
    with pytest.raises(ValueError, match="baseline_demos"):
        interval_label(Evidence(0.0, -1.0, 1.0, kind="demos"))


def test_co_primaries_that_disagree_leave_the_cell_inconclusive():
    paper = Cell(
        1,
        "paper",
        "",
        (Evidence(0.007, -0.035, 0.049), Evidence(-0.3, -9.7, 9.2, kind="demos", baseline_demos=20.2)),
    )
    assert cell_label(paper) == (INCONCLUSIVE, False)
    both = Cell(1, "x", "", (Evidence(0.0, -0.01, 0.02), Evidence(0.0, -0.02, 0.01)))
    assert cell_label(both) == (NOT_REPRODUCED, False)


def test_the_pre_specified_interval_labels_the_cell_before_any_post_hoc_one():
    cell = Cell(1, "x", "", (posthoc(0.1, 0.05, 0.15), Evidence(0.0, -0.01, 0.02)))
    assert cell_label(cell) == (NOT_REPRODUCED, False)
    assert cell_label(Cell(1, "x", "", (posthoc(0.0, -0.01, 0.02),))) == (NOT_REPRODUCED, True)
    assert cell_label(Cell(1, "x", "no runs")) == (NOT_TESTABLE, False)


def test_the_correlation_interval_is_fishers():
    low, high = correlation_interval(-0.32, 150)
    assert low == pytest.approx(-0.457, abs=0.001)
    assert high == pytest.approx(-0.168, abs=0.001)


def test_every_cell_of_every_claim_and_setting_is_labelled_once():
    keys = [(c.claim, c.setting, c.part) for c in CELLS]
    assert len(keys) == len(set(keys))
    assert {(c.claim, c.setting) for c in CELLS} == {
        (k, s) for k in range(1, 6) for s in {c.setting for c in CELLS}
    }


def test_the_results_page_holds_the_rules_table_verbatim():
    page = RESULTS_PAGE.read_text()
    start, end = "<!-- verdicts: python -m lab.verdicts -->\n", "\n<!-- /verdicts -->"
    assert start in page and end in page, f"docs/results.md lost its verdict markers: {start.strip()}"
    held = page.split(start, 1)[1].split(end, 1)[0]
    assert held == table_markdown(), "docs/results.md's verdict table differs: paste `python -m lab.verdicts`"
