"""Systematic sampling: picking a share of a sequence as evenly as a seeded offset allows.

Used for the expert's episodes under episode mixing and for the held-out episodes.
"""

from __future__ import annotations

import numpy as np


def systematic_picks(fraction: float, count: int, offset: float) -> np.ndarray:
    """Which of ``count`` items are picked at rate ``fraction`` for an offset in [0, 1) (a boolean array).

    Item ``j`` is picked when ``floor(fraction * (j + 1) + u)`` steps up from ``floor(fraction * j + u)``,
    so any ``n`` consecutive items hold ``floor(fraction * n)`` or ``ceil(fraction * n)`` picks, and
    appending items never changes the earlier picks.
    """
    level = np.floor(fraction * np.arange(count + 1) + offset)
    return level[1:] > level[:-1]
