"""The toy suite's expert: the optimal push towards the goal, against the wind."""

from __future__ import annotations

from typing import Any

import numpy as np

from lerobot_mtdagger.envs.toy import STEP_SIZE


class ToyExpert:
    """Pushes straight to the goal, cancelling the wind; stateless (labels any state)."""

    def reset(self) -> None:
        """The expert is stateless."""

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """``clip((goal - position - wind) / STEP_SIZE, -1, 1)`` from (x, y, goal, wind)."""
        state = np.asarray(privileged_state, dtype=np.float64)
        position, goal, wind = state[0:2], state[2:4], state[4:6]
        return np.clip((goal - position - wind) / STEP_SIZE, -1.0, 1.0).astype(np.float32)


def scripted_expert(suite: Any, task_name: str) -> ToyExpert:
    """The registry's factory for the ``toy`` suite family (``experts.registry``)."""
    return ToyExpert()
