"""The results page's verdict table: one labelling rule, its thresholds written once, every cell.

``python -m lab.verdicts`` (from ``experiments/``) prints the table that ``docs/results.md`` holds
between its ``verdicts`` markers; ``lab/tests/test_verdicts.py`` checks that the page holds exactly
this output, so a cell cannot carry a label the rule does not give.

The rule, for an interval of ``method - baseline`` oriented so that the paper's claim is positive:

- **reproduced**: the interval is above 0;
- **reversed**: the interval is below 0;
- **not reproduced**: the interval holds 0 and its upper end is below the margin (the claimed effect,
  had it been as large as the margin, would have shown);
- **inconclusive**: the interval holds 0 and reaches the margin, or the protocol was not fair to both
  arms;
- **not testable here**: the design gives no interval for the claim.

The analysis fixed before the runs (a study's ``run.sh``, or the toolkit's report as it stood before
them) labels the cell. Where none was fixed, an analysis chosen after the results labels it, marked
*post-hoc*, and can only say "not reproduced" or "inconclusive": a post-hoc interval above 0 is a lead
(inconclusive), one below 0 shows the claimed effect absent (not reproduced), never "reversed". Where
a cell has co-primary intervals, it takes their common label, or "inconclusive" if they differ.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

SUCCESS_MARGIN = 0.05
"""Margin for a difference in mean success (a fraction of episodes)."""
DEMOS_MARGIN_SHARE = 0.2
"""Margin for a difference in demos per task to a level: this share of the baseline's demos."""
CORRELATION_MARGIN = 0.3
"""Margin for a correlation between a scheduler's metric and success (claimed negative)."""

REPRODUCED = "reproduced"
REVERSED = "reversed"
NOT_REPRODUCED = "not reproduced"
INCONCLUSIVE = "inconclusive"
NOT_TESTABLE = "not testable here"


@dataclass(frozen=True)
class Evidence:
    """One interval a cell rests on, as the study README gives it.

    Attributes:
        estimate: The point estimate.
        low: The 95% interval's lower end.
        high: The 95% interval's upper end.
        kind: ``success`` (method - baseline in mean success), ``demos`` (method - baseline in demos
            per task to a level; the claim is negative) or ``correlation`` (Pearson r of the metric
            with success over task-seeds; the claim is negative).
        prespecified: Fixed before the runs.
        baseline_demos: The baseline's demos to the level (``demos`` only: its margin's base).
    """

    estimate: float
    low: float
    high: float
    kind: str = "success"
    prespecified: bool = True
    baseline_demos: float | None = None


@dataclass(frozen=True)
class Cell:
    """One cell of the table: a claim in one setting.

    Attributes:
        claim: The claim's row (1-5).
        setting: The column's key (:data:`SETTINGS`).
        text: What the cell says after its label: the comparison and its numbers.
        evidence: The intervals the label rests on (empty: not testable here).
        fair: The protocol was fair to both arms (one training search for all).
        part: A prefix naming the comparison when one cell holds several (``"vs uniform"``).
    """

    claim: int
    setting: str
    text: str
    evidence: tuple[Evidence, ...] = field(default_factory=tuple)
    fair: bool = True
    part: str = ""


def oriented(evidence: Evidence) -> tuple[float, float, float]:
    """The interval turned so that the claim is positive, and the margin in its units."""
    if evidence.kind == "success":
        return evidence.low, evidence.high, SUCCESS_MARGIN
    if evidence.kind == "demos":
        if evidence.baseline_demos is None:
            raise ValueError("a demos interval needs the baseline's demos (baseline_demos)")
        return -evidence.high, -evidence.low, DEMOS_MARGIN_SHARE * evidence.baseline_demos
    if evidence.kind == "correlation":
        return -evidence.high, -evidence.low, CORRELATION_MARGIN
    raise ValueError(f"unknown evidence kind {evidence.kind!r}: use success, demos or correlation")


def interval_label(evidence: Evidence, *, fair: bool = True) -> str:
    """The rule's label for one interval."""
    low, high, margin = oriented(evidence)
    if low > 0:
        label = REPRODUCED
    elif high < 0:
        label = REVERSED
    elif high < margin:
        label = NOT_REPRODUCED
    else:
        label = INCONCLUSIVE
    if not fair and label != NOT_REPRODUCED:
        return INCONCLUSIVE
    if not evidence.prespecified:
        return {REPRODUCED: INCONCLUSIVE, REVERSED: NOT_REPRODUCED}.get(label, label)
    return label


def cell_label(cell: Cell) -> tuple[str, bool]:
    """The cell's label and whether it rests on a post-hoc analysis."""
    if not cell.evidence:
        return NOT_TESTABLE, False
    fixed = [e for e in cell.evidence if e.prespecified]
    used = fixed or list(cell.evidence)
    labels = {interval_label(e, fair=cell.fair) for e in used}
    return (labels.pop() if len(labels) == 1 else INCONCLUSIVE), not fixed


def correlation_interval(r: float, n: int) -> tuple[float, float]:
    """A 95% interval for a Pearson r over ``n`` pairs (Fisher's z)."""
    z, half = math.atanh(r), 1.959964 / math.sqrt(n - 3)
    return math.tanh(z - half), math.tanh(z + half)


def correlation(r: float, n: int) -> Evidence:
    """A metric-success correlation as evidence (the report's standard analysis)."""
    low, high = correlation_interval(r, n)
    return Evidence(r, low, high, kind="correlation")


def posthoc(estimate: float, low: float, high: float) -> Evidence:
    """A mean-success interval from an analysis chosen after the results."""
    return Evidence(estimate, low, high, prespecified=False)


SETTINGS = {
    "mt10": "MT10 state ([README](../experiments/mt10-state-eval/README.md))",
    "mt50": "MT50 state ([README](../experiments/mt50-state-eval/README.md))",
    "plateau": "beyond plateau ([eval](../experiments/beyond-plateau-eval/README.md), "
    "[same search](../experiments/plateau-dagger-eval/README.md))",
    "drawers": "drawers, point cloud ([README](../experiments/drawers-eval/README.md))",
    "pixels": "MT10 pixels, matched training ([README](../experiments/pixels-matched-eval/README.md))",
    "paper": "paper's regime, imperfect-expert MT50 ([README](../experiments/paper-regime-eval/README.md))",
    "room": "where scheduling has room ([README](../experiments/scheduling-pays-eval/README.md))",
}
CLAIMS = {
    1: "1. Fewer demos than Uniform DAgger and than BC",
    2: "2. Larger gain on the hardest tasks",
    3: "3. The Kalman filter helps (need vs need_raw)",
    4: "4. Scheduler metrics track success",
    5: "5. Better on unseen drawers",
}
NO_DRAWERS = "no drawers"

CELLS: tuple[Cell, ...] = (
    # Claim 1. MT10 and MT50 fixed no single interval before the runs (their report gives one per budget).
    Cell(
        1,
        "mt10",
        "need - uniform over 9-33 demos +0.006 [-0.003, +0.016]; gain - uniform +0.002 "
        "[-0.014, +0.018]; to 90% need 1.09x uniform's demos",
        (posthoc(0.006, -0.003, 0.016),),
        part="vs uniform",
    ),
    Cell(
        1,
        "mt10",
        "need - BC over 9-33 demos -0.051 [-0.071, -0.031]; to 90% need 1.77x BC's demos",
        (posthoc(-0.051, -0.071, -0.031),),
        part="vs BC",
    ),
    Cell(
        1,
        "mt50",
        "need - uniform over 9-33 demos +0.018 [+0.000, +0.035], a lead; gain - uniform +0.014 "
        "[-0.010, +0.039]; to 90% need 0.73x uniform's demos",
        (posthoc(0.018, 0.0001, 0.035),),
        part="vs uniform",
    ),
    Cell(
        1,
        "mt50",
        "need - BC over 9-33 demos -0.013 [-0.059, +0.032]; to 90% need 1.41x BC's demos",
        (posthoc(-0.013, -0.059, 0.032),),
        part="vs BC",
    ),
    Cell(
        1,
        "plateau",
        "need - best BC over 45-63 demos -0.014 [-0.040, +0.011], each arm with the training "
        "the same search chose",
        (Evidence(-0.014, -0.040, 0.011),),
        part="vs BC",
    ),
    Cell(
        1,
        "plateau",
        "need - uniform +0.014 [-0.004, +0.032] (secondary), each with its chosen training",
        (Evidence(0.014, -0.004, 0.032),),
        part="vs uniform",
    ),
    Cell(
        1,
        "drawers",
        "need - BC over 20-30 demos per drawer +0.017 [-0.105, +0.139]; need - uniform +0.003 "
        "[-0.070, +0.076]",
        (Evidence(0.017, -0.105, 0.139), Evidence(0.003, -0.070, 0.076)),
    ),
    Cell(
        1,
        "pixels",
        "need - uniform over 20-60 demos +0.011 [-0.008, +0.029]; gain - uniform -0.003 [-0.043, +0.036]",
        (Evidence(0.011, -0.008, 0.029),),
        part="vs uniform",
    ),
    Cell(
        1,
        "pixels",
        "need - BC +0.025 [-0.080, +0.131]; at 60 demos BC .798 above every DAgger arm's .73-.76 in mean",
        (Evidence(0.025, -0.080, 0.131),),
        part="vs BC",
    ),
    Cell(
        1,
        "paper",
        "co-primaries: need - uniform over 6-30 demos +0.007 [-0.035, +0.049]; demos to 0.80 "
        "need - uniform -0.3 [-9.7, +9.2] of uniform's 20.2",
        (Evidence(0.007, -0.035, 0.049), Evidence(-0.3, -9.7, 9.2, kind="demos", baseline_demos=20.2)),
        part="vs uniform",
    ),
    Cell(
        1,
        "paper",
        "need - BC +0.033 [-0.035, +0.102] (secondary)",
        (Evidence(0.033, -0.035, 0.102),),
        part="vs BC",
    ),
    Cell(
        1,
        "room",
        "no setting two cores can run leaves a scheduler half of its headroom: by its pre-specified rule "
        "the study ran nothing (best share 41%, paper regime; 32%, MT10 pixels)",
    ),
    # Claim 2: the report's hardest-task rows, or the study's own fixed subset.
    Cell(
        2,
        "mt10",
        "2 hardest tasks at 33 demos: need - uniform -0.060 [-0.430, +0.310], gain - uniform "
        "-0.055 [-0.233, +0.123]",
        (Evidence(-0.060, -0.430, 0.310), Evidence(-0.055, -0.233, 0.123)),
    ),
    Cell(
        2,
        "mt50",
        "2 hardest tasks at 33 demos: need - uniform -0.092 [-0.350, +0.167], gain - uniform "
        "-0.117 [-0.530, +0.297]; post-hoc, the hardest fifth: need - uniform +0.063 [-0.000, +0.127]",
        (Evidence(-0.092, -0.350, 0.167), Evidence(-0.117, -0.530, 0.297)),
    ),
    Cell(
        2,
        "plateau",
        "2 hardest tasks at 63 demos: need - uniform +0.130 [-0.092, +0.352] against +0.005 on the rest",
        (Evidence(0.130, -0.092, 0.352),),
    ),
    Cell(
        2,
        "drawers",
        "2 hardest drawers at 30 demos: need - uniform -0.017 [-0.416, +0.383], gain - "
        "uniform +0.083 [-0.223, +0.390]",
        (Evidence(-0.017, -0.416, 0.383), Evidence(0.083, -0.223, 0.390)),
    ),
    Cell(
        2,
        "pixels",
        "3 hardest tasks at 60 demos: need - uniform -0.017 [-0.545, +0.512], gain - uniform "
        "-0.050 [-0.302, +0.202]",
        (Evidence(-0.017, -0.545, 0.512), Evidence(-0.050, -0.302, 0.202)),
    ),
    Cell(
        2,
        "paper",
        "5 hardest tasks over 6-30 demos: need - uniform -0.001 [-0.103, +0.101]",
        (Evidence(-0.001, -0.103, 0.101),),
    ),
    Cell(2, "room", "not part of its design"),
    # Claim 3.
    Cell(
        3, "mt10", "need - need_raw -0.015 [-0.065, +0.035] at 33 demos", (Evidence(-0.015, -0.065, 0.035),)
    ),
    Cell(
        3,
        "mt50",
        "need - need_raw +0.003 [-0.025, +0.030] over 9-33 demos",
        (Evidence(0.003, -0.025, 0.030),),
    ),
    Cell(3, "plateau", "no need_raw runs"),
    Cell(3, "drawers", "one Kalman observation keeps the raw ranks: need = need_raw by construction"),
    Cell(3, "pixels", "no need_raw runs"),
    Cell(
        3,
        "paper",
        "need - need_raw +0.009 [-0.028, +0.047] over 6-30 demos, derived from the arms",
        (posthoc(0.009, -0.028, 0.047),),
    ),
    Cell(3, "room", "no need_raw arm"),
    # Claim 4: r over task-seeds, the report's analysis; intervals by Fisher's z.
    Cell(
        4,
        "mt10",
        "TN r = -0.78, PG r = -0.56 (50 task-seeds)",
        (correlation(-0.78, 50), correlation(-0.56, 50)),
    ),
    Cell(
        4,
        "mt50",
        "TN r = -0.66, PG r = -0.32 (150 task-seeds)",
        (correlation(-0.66, 150), correlation(-0.32, 150)),
    ),
    Cell(4, "plateau", "TN r = -0.68 (50 task-seeds; no PG runs)", (correlation(-0.68, 50),)),
    Cell(
        4,
        "drawers",
        "TN r = -0.03, PG r = +0.03 (33 drawer-seeds, most at 0.9-1.0 success)",
        (correlation(-0.03, 33), correlation(0.03, 33)),
    ),
    Cell(
        4,
        "pixels",
        "TN r = -0.99 (a filtered failure rate: partly by construction), PG r = -0.66 (30)",
        (correlation(-0.99, 30), correlation(-0.66, 30)),
    ),
    Cell(
        4,
        "paper",
        "TN r = -0.83, PG r = -0.40 (129 task-seeds)",
        (correlation(-0.83, 129), correlation(-0.40, 129)),
    ),
    Cell(4, "room", "not part of its design"),
    # Claim 5.
    Cell(5, "mt10", NO_DRAWERS),
    Cell(5, "mt50", NO_DRAWERS),
    Cell(5, "plateau", NO_DRAWERS),
    Cell(
        5,
        "drawers",
        "unseen drawers over 20-30 demos: need - BC -0.088 [-0.408, +0.233]; trainings on the "
        "same data differ by SD 0.10 there",
        (Evidence(-0.088, -0.408, 0.233),),
    ),
    Cell(5, "pixels", NO_DRAWERS),
    Cell(5, "paper", NO_DRAWERS),
    Cell(5, "room", NO_DRAWERS),
)


def cell_markdown(cell: Cell) -> str:
    """``[part: ]**label** (text)``, with *post-hoc* where the label rests on such an analysis."""
    label, is_posthoc = cell_label(cell)
    prefix = f"{cell.part}: " if cell.part else ""
    mark = ", *post-hoc*" if is_posthoc else ""
    return f"{prefix}**{label}**{mark} ({cell.text})"


def rule_markdown() -> str:
    """The rule as the page states it, its thresholds filled in from this module's constants."""
    return (
        "Every cell is labelled by one rule, applied to the 95% interval of method - baseline turned so "
        "that the paper's claim is positive: **reproduced** if the interval is above 0; **reversed** if "
        "below 0; **not reproduced** if it holds 0 and its upper end stays below the margin (a claimed "
        "effect that large would have shown); **inconclusive** if it holds 0 and reaches the margin, or if "
        "the protocol was not fair to both arms; **not testable here** if the design gives no interval. "
        f"Margins: {SUCCESS_MARGIN:.2f} in mean success; {DEMOS_MARGIN_SHARE:.0%} of the baseline's demos "
        f"per task to a level; r = {CORRELATION_MARGIN:.1f} for a metric's correlation with success "
        "(claimed negative; 95% interval by Fisher's z over task-seeds, which are not independent: "
        "tasks share a seed's policy). The analysis fixed before the runs (the study's `run.sh`, or the "
        "toolkit's report as it stood before them) labels the cell; where none was fixed, one chosen "
        "after the results does, marked *post-hoc*, and it can only say not reproduced (its interval "
        "below the margin, or below 0) or inconclusive (a post-hoc interval above 0 is a lead). Co-primary "
        "intervals that disagree leave the cell inconclusive. The study READMEs keep the labels their own "
        "`run.sh` rules gave, which may differ."
    )


def table_markdown(cells: tuple[Cell, ...] = CELLS) -> str:
    """The rule, then the verdict table: one row per claim and one column per setting."""
    lines = [
        rule_markdown(),
        "",
        "| claim | " + " | ".join(SETTINGS.values()) + " |",
        "|---" * (len(SETTINGS) + 1) + "|",
    ]
    for claim, name in CLAIMS.items():
        row = [
            "; ".join(cell_markdown(c) for c in cells if c.claim == claim and c.setting == key)
            for key in SETTINGS
        ]
        lines.append(f"| {name} | " + " | ".join(row) + " |")
    return "\n".join(lines)


if __name__ == "__main__":
    print(table_markdown())
