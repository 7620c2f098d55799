"""One line of paired differences over seeds, for the studies' table scripts."""

from __future__ import annotations

import math
from collections.abc import Sequence

from lerobot_mtdagger.analysis.stats import format_difference, paired_difference


def paired_line(name: str, pairs: Sequence[tuple[float, float]]) -> str:
    """``name: +0.010 / -0.020; <format_difference>``: per-seed differences, then their paired mean.

    Args:
        name: The line's label, e.g. ``"need - bc"``.
        pairs: One ``(method, baseline)`` value per seed; a seed with NaN on either side is left out.

    Returns:
        The line, or ``"<name>: fewer than 2 seeds have both"`` when fewer than two seeds are complete.
    """
    complete = [(a, b) for a, b in pairs if not (math.isnan(a) or math.isnan(b))]
    if len(complete) < 2:
        return f"{name}: fewer than 2 seeds have both"
    first, second = zip(*complete, strict=True)
    per_seed = " / ".join(f"{a - b:+.3f}" for a, b in complete)
    return f"{name}: {per_seed}; {format_difference(paired_difference(first, second))}"
