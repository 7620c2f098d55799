"""The paper's task rule: keep only the tasks whose expert succeeds often enough (``--expert.min_success``).

Each task's expert, as the run uses it, is measured on ``--expert.success_episodes`` episodes of its
own seed stream (``EXPERT_CHECK_STREAM``). The result goes into the experiment as
``expert_check.json``, which a resume reads back; every round's record holds the kept tasks.
"""

from __future__ import annotations

import json
import logging
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any

from lerobot_mtdagger.datasets.experiment_dir import EXPERT_CHECK_FILE
from lerobot_mtdagger.experts import make_expert, run_expert_episode
from lerobot_mtdagger.runner.rollout.collect import episode_seed
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.seeds import EXPERT_CHECK_STREAM

logger = logging.getLogger(__name__)

__all__ = ["EXPERT_CHECK_FILE", "ExpertCheck", "expert_success", "measure_expert_check"]


@dataclass(frozen=True)
class ExpertCheck:
    """Which tasks a run kept, and why.

    Attributes:
        min_success: The threshold (``--expert.min_success``).
        episodes: Episodes measured per task.
        success: Each task's expert success rate, in the suite's order.
        kept: The tasks at or above the threshold, in the suite's order.
    """

    min_success: float
    episodes: int
    success: dict[str, float]
    kept: list[str]

    @property
    def dropped(self) -> list[str]:
        """The tasks below the threshold."""
        return [task for task in self.success if task not in self.kept]

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (``expert_check.json``)."""
        return {**asdict(self), "dropped": self.dropped}

    @classmethod
    def read(cls, path: Path) -> ExpertCheck:
        """Reads ``expert_check.json`` (``UserError`` naming it if it cannot be read)."""
        try:
            values = json.loads(path.read_text())
            return cls(
                min_success=float(values["min_success"]),
                episodes=int(values["episodes"]),
                success={str(k): float(v) for k, v in values["success"].items()},
                kept=[str(task) for task in values["kept"]],
            )
        except (OSError, json.JSONDecodeError, KeyError, TypeError, ValueError) as error:
            raise UserError(
                f"{path} cannot be read ({type(error).__name__}: {error}): it chose this experiment's "
                "tasks; restore it, or start a new --output_dir."
            ) from None


def expert_success(suite: Any, task_index: int, episodes: int, seed: int) -> float:
    """Success rate of one task's expert (with the suite's noise) over ``episodes`` checked episodes."""
    task = suite.task_names[task_index]
    env, expert = suite.make_env(task), make_expert(suite, task)
    noise = suite.expert_noise
    successes = 0
    try:
        for episode in range(episodes):
            reset_seed = episode_seed(seed, EXPERT_CHECK_STREAM, 0, task_index, episode)
            process = None
            if noise is not None:  # a key of its own length: none of the run's episodes' noise
                key = (EXPERT_CHECK_STREAM, 0, task_index, episode)
                process = noise.episode_process(key, env.action_space.low, env.action_space.high, task=task)
            successes += run_expert_episode(env, expert, reset_seed, noise=process).success
    finally:
        env.close()
    return successes / episodes


def measure_expert_check(suite: Any, min_success: float, episodes: int, seed: int) -> ExpertCheck:
    """Measures every task's expert, keeping those at or above ``min_success`` (``UserError`` if none)."""
    success: dict[str, float] = {}
    for task_index, task in enumerate(suite.task_names):
        success[task] = expert_success(suite, task_index, episodes, seed)
        logger.info("expert success %s: %.3f over %d episodes", task, success[task], episodes)
    kept = [task for task, rate in success.items() if rate >= min_success]
    if not kept:
        best = max(success, key=success.__getitem__)
        raise UserError(
            f"No task's expert reaches --expert.min_success={min_success} (best: {best} at "
            f"{success[best]:.2f} over {episodes} episodes): lower the threshold or the expert noise."
        )
    return ExpertCheck(min_success=min_success, episodes=episodes, success=success, kept=kept)
