"""The schedulers built to use headroom: the paper's rule with its normalisation exposed, the
learning-curve scheduler and the learnability baseline."""

from __future__ import annotations

import itertools
import json

import numpy as np
import pytest

from lerobot_mtdagger.learning_curve import CurvePrior, fit_logistic_curves, greedy_split
from lerobot_mtdagger.scheduler import (
    SchedulerConfig,
    allocation_mismatches,
    make_scheduler,
    recompute_allocation,
)


def _need_split(success: list[float], normalization: str) -> list[int]:
    scheduler = make_scheduler("need_raw", len(success), normalization=normalization)
    scheduler.update(success_rate=success, episodes=[20] * len(success))
    return scheduler.allocate(40).episodes_per_task


def test_rank_normalisation_gives_the_same_split_whatever_the_spread():
    narrow, wide = [0.80, 0.85, 0.90, 0.95], [0.05, 0.40, 0.70, 0.95]
    assert _need_split(narrow, "rank") == _need_split(wide, "rank")


def test_metric_normalisation_widens_the_split_with_the_spread():
    narrow, wide = (
        _need_split([0.80, 0.85, 0.90, 0.95], "none"),
        _need_split([0.05, 0.40, 0.70, 0.95], "none"),
    )
    assert max(wide) - min(wide) > max(narrow) - min(narrow)
    assert wide[0] == max(wide)  # the hardest task gets most


def test_normalisation_out_of_range_is_refused_naming_the_choices():
    with pytest.raises(ValueError, match=r"scheduler.normalization must be one of \['rank', 'none'\]"):
        make_scheduler("need", 3, normalization="zscore")


def test_learnability_favours_tasks_near_even_odds():
    scheduler = make_scheduler("learnability", 3)
    scheduler.update(success_rate=[0.0, 0.5, 1.0], episodes=[20, 20, 20])
    counts = scheduler.allocate(30).episodes_per_task
    assert counts[1] == max(counts) and counts[1] > counts[0] and counts[1] > counts[2]


def test_curve_fit_recovers_a_known_shared_slope_curve():
    intercept, slope = np.array([-3.0, -1.0, 0.5]), 1.2
    demos = np.array([[2, 2, 2], [4, 4, 4], [8, 8, 8], [16, 16, 16], [32, 32, 32]], dtype=float)
    success = 1.0 / (1.0 + np.exp(-(intercept[None, :] + slope * np.log(demos))))
    fitted = fit_logistic_curves(demos, success, np.full_like(demos, 10_000), CurvePrior(prior_scale=10.0))
    np.testing.assert_allclose(fitted.intercept, intercept, atol=0.02)
    assert fitted.slope == pytest.approx(slope, abs=0.01)


def test_curve_fit_shrinks_a_task_seen_once_toward_the_others():
    demos = np.full((1, 3), 3.0)
    weak = fit_logistic_curves(
        demos, np.array([[0.0, 0.5, 1.0]]), np.full((1, 3), 2), CurvePrior(prior_scale=0.1)
    )
    loose = fit_logistic_curves(
        demos, np.array([[0.0, 0.5, 1.0]]), np.full((1, 3), 2), CurvePrior(prior_scale=5.0)
    )
    assert np.ptp(weak.intercept) < 0.1 < np.ptp(loose.intercept)


def test_greedy_split_matches_brute_force_on_concave_curves():
    extra = np.arange(7)
    curves = np.stack([1 - np.exp(-extra / d) for d in (0.5, 2.0, 6.0)])  # (3, 7), concave
    counts, _ = greedy_split(curves, budget=6, n_min=1)
    best = max(
        (c for c in itertools.product(range(1, 5), repeat=3) if sum(c) == 6),
        key=lambda c: curves[np.arange(3), list(c)].sum(),
    )
    assert curves[np.arange(3), counts].sum() == pytest.approx(curves[np.arange(3), list(best)].sum())
    assert counts.sum() == 6 and counts.min() >= 1


def test_greedy_split_looks_past_a_flat_start():
    flat_then_rising = np.array([[0.0, 0.0, 0.0, 0.9, 0.9], [0.0, 0.1, 0.2, 0.3, 0.4]])
    counts, _ = greedy_split(flat_then_rising, budget=3, n_min=0)
    assert counts.tolist() == [3, 0]


def _curve_scheduler_after(rounds: int):
    scheduler = make_scheduler("curve", 3, n_min=1)
    truth = [lambda n: 1 - np.exp(-n / 2), lambda n: 1 - np.exp(-n / 10), lambda n: 0.02 * n / (n + 100)]
    demos = np.array([3.0, 3.0, 3.0])
    for _ in range(rounds):
        success = [f(n) for f, n in zip(truth, demos, strict=True)]
        allocation = scheduler.allocate(15) if scheduler.num_updates else None
        scheduler.update(
            success_rate=success, episodes=[200] * 3, demos=demos.tolist(), demos_so_far=demos.tolist()
        )
        if allocation is not None:
            demos = demos + np.asarray(allocation.episodes_per_task)
    return scheduler


def test_curve_scheduler_gives_most_to_the_task_still_learning():
    counts = _curve_scheduler_after(4).allocate(15).episodes_per_task
    # Task 0 is saturated, task 2 is not learnable within reach: task 1 should get the most.
    assert counts[1] == max(counts)
    assert counts[0] >= 1 and counts[2] >= 1


def test_curve_scheduler_splits_evenly_before_any_measurement():
    allocation = make_scheduler("curve", 4).allocate(12)
    assert allocation.episodes_per_task == [3, 3, 3, 3]


def test_curve_scheduler_needs_the_demos_behind_each_measurement():
    with pytest.raises(ValueError, match="pass demos="):
        make_scheduler("curve", 2).update(success_rate=[0.5, 0.5], episodes=[2, 2])


def test_curve_allocation_is_recomputed_and_a_tampered_history_is_caught():
    record = json.loads(json.dumps(_curve_scheduler_after(3).allocate(15).to_dict()))
    assert record["options"] == {
        "prior_scale": 1.5,
        "slope_mean": 1.0,
        "slope_scale": 1.0,
        "task_slope_scale": 0.1,
    }
    assert allocation_mismatches(record) == []
    record["history"]["success"][-1][2] = 1.0
    assert allocation_mismatches(record) != []


def test_curve_options_are_rebuilt_from_the_record():
    scheduler = make_scheduler("curve", 2, prior_scale=0.5)
    scheduler.update(success_rate=[0.2, 0.6], episodes=[5, 5], demos=[3, 3])
    record = scheduler.allocate(6).to_dict()
    assert recompute_allocation(record).config().prior_scale == 0.5


@pytest.mark.parametrize(
    "field, value", [("prior_scale", 0.0), ("slope_scale", -1.0), ("slope_mean", float("nan"))]
)
def test_curve_options_out_of_range_are_refused(field, value):
    with pytest.raises(ValueError, match=f"scheduler.{field}"):
        make_scheduler("curve", 2, **{field: value})


def test_old_records_without_the_new_fields_still_recompute():
    scheduler = make_scheduler("need", 3)
    scheduler.update(success_rate=[0.0, 0.5, 1.0], episodes=[2, 2, 2])
    record = scheduler.allocate(12).to_dict()
    assert not {"options", "history", "demos_so_far"} & set(record)
    assert allocation_mismatches(record) == []


def test_new_methods_are_registered():
    assert {"curve", "learnability"} <= set(SchedulerConfig.get_known_choices())
