"""``lab.paired``: the line of paired differences the study scripts print."""

from __future__ import annotations

from lab.paired import paired_line


def test_a_paired_line_gives_each_seed_s_difference_and_skips_seeds_missing_a_side():
    """The line the study scripts print: differences 0.3, 0.2, 0.1 -> +0.200 [-0.048, +0.448]."""
    nan = float("nan")
    pairs = [(0.9, 0.6), (0.8, 0.6), (nan, 0.5), (0.7, 0.6)]
    assert paired_line("need - bc", pairs) == "need - bc: +0.300 / +0.200 / +0.100; +0.200 [-0.048, +0.448]"
    assert paired_line("need - bc", [(0.9, 0.6), (0.8, nan)]) == "need - bc: fewer than 2 seeds have both"
