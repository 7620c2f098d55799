"""Headroom: the best split of the same demos against an even split, from measured learning curves."""

from __future__ import annotations

import csv
from pathlib import Path

import numpy as np
import pytest

from lerobot_mtdagger.analysis.headroom import (
    TaskPoint,
    best_splits,
    fit_curves,
    headroom_at,
    held_out_headroom,
    points_from_rows,
)
from lerobot_mtdagger.learning_curve import isotonic
from lerobot_mtdagger.utils.errors import UserError

PAPER_REGIME = Path(__file__).parents[1] / "experiments" / "paper-regime-eval" / "records"


def points(curves: dict[int, dict[int, float]], seed: int = 0, episodes: int = 20) -> list[TaskPoint]:
    """Points of ``{task: {demos: success}}``."""
    return [
        TaskPoint(task, seed, demos, success, episodes)
        for task, curve in curves.items()
        for demos, success in curve.items()
    ]


def test_isotonic_pools_adjacent_violators_by_weight():
    np.testing.assert_allclose(isotonic(np.array([0.5, 0.3, 0.8]), np.ones(3)), [0.4, 0.4, 0.8])
    np.testing.assert_allclose(isotonic(np.array([0.6, 0.0]), np.array([3.0, 1.0])), [0.45, 0.45])


def test_identical_tasks_leave_no_headroom():
    curve = {3: 0.2, 6: 0.5, 12: 0.7, 30: 0.9}
    curves = fit_curves(points({0: curve, 1: curve, 2: curve}), ["a", "b", "c"])
    splits = best_splits(curves)
    for budget in (3, 6, 10, 30):
        headroom = headroom_at(splits, budget)
        assert headroom.gain == pytest.approx(0.0, abs=1e-12)
        assert headroom.demos_to_match == pytest.approx(budget)


def test_a_small_case_solved_by_hand():
    # Task a learns late (0 / .2 / 1 at 1 / 2 / 3 demos), task b early (.5 / .6 / .7).
    curves = fit_curves(points({0: {1: 0.0, 2: 0.2, 3: 1.0}, 1: {1: 0.5, 2: 0.6, 3: 0.7}}), ["a", "b"])
    headroom = headroom_at(best_splits(curves), 2)
    # Even: (.2 + .6) / 2 = .4; best of 4 demos: a 3, b 1 -> (1 + .5) / 2 = .75.
    assert headroom.even == pytest.approx(0.4) and headroom.best == pytest.approx(0.75)
    assert headroom.gain == pytest.approx(0.35) and headroom.split == (3, 1)
    # 3 demos in all reach at most .35 (a 2, b 1): the even split's .4 needs all 4.
    assert headroom.demos_to_match == pytest.approx(2.0) and headroom.saving == pytest.approx(0.0)


def test_the_best_split_is_the_brute_force_optimum():
    rng = np.random.default_rng(0)
    table = {t: dict(zip([2, 4, 6], np.sort(rng.uniform(size=3)), strict=True)) for t in range(3)}
    curves = fit_curves(points(table), ["a", "b", "c"])
    splits = best_splits(curves)
    grid = range(curves.low, curves.high + 1)
    for total in range(3 * curves.low, 3 * curves.high + 1):
        brute = max(
            curves.at(np.array([x, y, total - x - y])).mean()
            for x in grid
            for y in grid
            if curves.low <= total - x - y <= curves.high
        )
        assert splits.value[total - 3 * curves.low] == pytest.approx(brute)
        assert splits.split(total).sum() == total


def test_held_out_headroom_of_identical_seeds_is_the_in_sample_one_and_needs_two_seeds():
    table = {0: {3: 0.1, 9: 0.9}, 1: {3: 0.6, 9: 0.7}}
    both = points(table, seed=0) + points(table, seed=1)
    (estimate,) = held_out_headroom(both, ["a", "b"], [6])
    # Even: (.5 + .65) / 2; best of 12 demos: a 9, b 3 -> (.9 + .6) / 2; every fold agrees.
    assert estimate.mean == pytest.approx(0.175) and estimate.high - estimate.low == pytest.approx(0.0)
    with pytest.raises(UserError, match="two or more seeds"):
        held_out_headroom(points(table), ["a", "b"], [6])


@pytest.mark.parametrize(
    "table, match",
    [
        ({0: {3: 0.1}, 1: {3: 0.2, 6: 0.5}}, "measured at 1 budget"),
        ({0: {3: 0.1, 6: 0.2}}, r"No measured point for task\(s\) \['b'\]"),
        ({0: {3: 0.1, 6: 0.2}, 1: {9: 0.5, 12: 0.6}}, "share no stretch of demos"),
    ],
)
def test_curves_that_cannot_give_a_headroom_are_refused(table, match):
    with pytest.raises(UserError, match=match):
        fit_curves(points(table), ["a", "b"])


def test_a_budget_outside_the_measured_range_is_refused():
    curves = fit_curves(points({0: {3: 0.1, 6: 0.2}, 1: {3: 0.3, 6: 0.5}}), ["a", "b"])
    with pytest.raises(UserError, match="outside the measured range 3-6"):
        headroom_at(best_splits(curves), 9)


def test_a_success_rate_out_of_range_is_refused():
    with pytest.raises(UserError, match="success 1.5"):
        fit_curves([TaskPoint(0, 0, 3, 1.5, 20), TaskPoint(0, 0, 6, 0.5, 20)], ["a"])


def _paper_regime_rows() -> list[dict]:
    rows = []
    for seed in range(3):
        with open(PAPER_REGIME / f"cosine-seed{seed}" / "results.csv") as file:
            rows += [row | {"bc": row["bc"] == "True"} for row in csv.DictReader(file)]
    return rows


def test_the_paper_regime_headroom_is_about_what_the_records_showed():
    """BC's curves (and DAgger's round 0 at 3 demos), pooled over seeds 0-2, isotonic, interpolated."""
    rows = _paper_regime_rows()
    task_points = points_from_rows(rows, "bc")
    curves = fit_curves(task_points, [str(i) for i in range(43)])
    assert (curves.low, curves.high) == (3, 30)
    splits = best_splits(curves)
    gains = [headroom_at(splits, budget).gain for budget in (6, 12, 18, 24, 30)]
    np.testing.assert_allclose(gains, [0.045, 0.069, 0.089, 0.027, 0.0], atol=0.002)
    held_out = {
        h.demos_per_task: h for h in held_out_headroom(task_points, curves.task_names, [6, 12, 18, 24])
    }
    assert all(-0.03 <= h.mean <= 0.03 and h.low < 0 < h.high for h in held_out.values())


def test_a_report_whose_runs_cannot_give_curves_says_why_in_one_line(tmp_path):
    from lerobot_mtdagger.analysis.headroom_report import HEADROOM_FILE, write_headroom

    row = {"method": "bc", "bc": True, "seed": 0, "round": 0, "demos_per_task": [5, 5]}
    lines, figure = write_headroom(
        [row | {"eval_success": [0.5, 0.7], "eval_episodes_per_task": 10}], ["a", "b"], tmp_path
    )
    assert figure is None and not (tmp_path / HEADROOM_FILE).exists()
    assert "Not computed: Task 'a' was measured at 1 budget(s)" in lines[2]
