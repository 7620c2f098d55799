"""Statistics over seeds, checked against values worked by hand."""

from __future__ import annotations

import math

import pytest

from lerobot_mtdagger.analysis.stats import (
    Interval,
    correlation,
    demos_to_reach,
    format_difference,
    mean_interval,
    paired_difference,
)


def test_mean_interval_of_1_2_3():
    # mean 2, s = 1, sem = 1 / sqrt(3) = 0.577350, t(0.975, df=2) = 4.302653: half width 2.484138
    interval = mean_interval([1.0, 2.0, 3.0])
    assert interval.mean == pytest.approx(2.0)
    assert interval.low == pytest.approx(-0.484138, abs=1e-6)
    assert interval.high == pytest.approx(4.484138, abs=1e-6)
    assert interval.n == 3 and not interval.excludes_zero()


def test_one_seed_has_a_mean_and_no_interval():
    interval = mean_interval([0.7])
    assert interval.mean == 0.7 and interval.n == 1
    assert math.isnan(interval.low) and math.isnan(interval.high) and not interval.excludes_zero()


@pytest.mark.parametrize(
    ("interval", "text"),
    [
        (Interval(0.012, -0.004, 0.028, 3), "+0.012 [-0.004, +0.028]"),
        (Interval(0.05, 0.01, 0.09, 3), "+0.050 [+0.010, +0.090] *"),
        (Interval(-0.05, -0.09, -0.01, 3), "-0.050 [-0.090, -0.010] *"),
        (Interval(0.7, math.nan, math.nan, 1), "+0.700 (one seed, no interval)"),
    ],
)
def test_a_difference_is_marked_only_where_its_interval_excludes_zero(interval, text):
    assert format_difference(interval) == text


def test_paired_difference_of_four_seeds():
    # differences 0.1 0.2 0.1 0.0: mean 0.1, s = sqrt(0.02 / 3) = 0.0816497, sem = 0.0408248,
    # t(0.975, df=3) = 3.182446: half width 0.129923
    interval = paired_difference([0.8, 0.9, 0.7, 0.6], [0.7, 0.7, 0.6, 0.6])
    assert interval.mean == pytest.approx(0.1)
    assert interval.low == pytest.approx(-0.029923, abs=1e-6)
    assert interval.high == pytest.approx(0.229923, abs=1e-6)
    assert not interval.excludes_zero()
    assert paired_difference([0.9, 0.8, 0.85], [0.5, 0.5, 0.5]).excludes_zero()


def test_demos_to_reach_interpolates_the_first_crossing():
    demos, success = [3, 6, 9, 12], [0.5, 0.6, 0.8, 0.9]
    assert demos_to_reach(demos, success, 0.7) == pytest.approx(7.5)  # 6 + (0.1 / 0.2) * 3
    assert demos_to_reach(demos, success, 0.5) == 3.0  # the first point already reaches it
    assert demos_to_reach(demos, success, 0.95) is None  # never reached: reported, not dropped
    # a curve that dips: the FIRST crossing counts, 3 + (0.2 / 0.3) * 3 = 5
    assert demos_to_reach([3, 6, 9, 12], [0.5, 0.8, 0.6, 0.9], 0.7) == pytest.approx(5.0)


def test_correlation():
    assert correlation([1, 2, 3], [3, 2, 1]) == pytest.approx(-1.0)
    assert correlation([1, 2, 3, 4], [1, 3, 2, 4]) == pytest.approx(0.8)  # cov 1.0 / (1.118 * 1.118)
    assert math.isnan(correlation([1, 1, 1], [1, 2, 3]))


@pytest.mark.parametrize(
    ("call", "match"),
    [
        (lambda: mean_interval([]), "at least one seed"),
        (lambda: mean_interval([0.5, math.nan]), "NaN"),
        (lambda: paired_difference([1.0], [1.0, 2.0]), "one pair per seed"),
        (lambda: demos_to_reach([3, 3], [0.1, 0.2], 0.5), "must increase"),
    ],
)
def test_bad_input_is_a_clear_error(call, match):
    with pytest.raises(ValueError, match=match):
        call()
