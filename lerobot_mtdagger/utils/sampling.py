"""Systematic sampling: picking a given share of a sequence as evenly as a seeded offset allows.

Used where a share of episodes must be spread evenly rather than left to independent coins: the
expert's episodes under episode mixing (``workers.expert_episode_coin``) and the held-out episodes
(``train.heldout_episodes``).
"""

from __future__ import annotations

import numpy as np


def systematic_picks(fraction: float, count: int, offset: float) -> np.ndarray:
    """Which of ``count`` items in order are picked at rate ``fraction``, for an offset ``u`` in [0, 1).

    Item ``j`` is picked when ``floor(fraction * (j + 1) + u)`` steps up from ``floor(fraction * j + u)``,
    so any ``n`` consecutive items hold ``floor(fraction * n)`` or ``ceil(fraction * n)`` picks, and
    appending items never changes the picks among the earlier ones.

    Returns:
        A boolean array of length ``count``.
    """
    level = np.floor(fraction * np.arange(count + 1) + offset)
    return level[1:] > level[:-1]
