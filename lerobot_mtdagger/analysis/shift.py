"""Covariate shift of a policy: its action error on the states it reaches against on the expert's states.

``measure_shift`` runs, on the evaluation reset seeds, the policy with the expert labelling every
state, and the expert from the same seeds; the mean squared action error ``|clip(pi(s)) - pi*(s)|^2``
per frame gives, per task, the shift factor own / expert. Near 1 relabelled rollouts add little over
more demonstrations; well above 1 the policy's own states are where it goes wrong. Actions are
clipped as the env clips them; episodes end at the first success, as in evaluation.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.runner.rollout.collect import EpisodeOptions, PolicyFn, run_episodes, success_by_task
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers, Episode
from lerobot_mtdagger.utils.seeds import EVAL_STREAM


@dataclass
class ShiftResult:
    """Per-task action errors of a policy on its own states and on the expert's (mean squared, per frame).

    Attributes:
        success: The policy's success rate per task on the measured episodes.
        own_error_succeeded: ``own_error`` on its successful episodes only (None: none succeeded).
        own_error_failed: The same on its failed episodes only (None: none failed).
        own_error_by_dimension: ``own_error`` per action dimension (it sums to ``own_error``).
        episodes: Episodes per task, of the policy and of the expert each.
    """

    task_names: list[str]
    success: list[float]
    own_error: list[float]
    own_error_succeeded: list[float | None]
    own_error_failed: list[float | None]
    expert_error: list[float]
    own_error_by_dimension: list[list[float]]
    expert_error_by_dimension: list[list[float]]
    episodes: int
    seed: int

    @property
    def ratio(self) -> list[float]:
        """Own / expert error per task (1.0 where both are 0, inf where only the expert's is 0)."""
        return [
            shift_ratio(own, expert) for own, expert in zip(self.own_error, self.expert_error, strict=True)
        ]

    @property
    def mean_ratio(self) -> float:
        """Mean own error over tasks / mean expert error over tasks."""
        return shift_ratio(float(np.mean(self.own_error)), float(np.mean(self.expert_error)))

    @property
    def median_ratio(self) -> float:
        """The median task's own / expert ratio (robust to a few stuck tasks)."""
        return float(np.median(self.ratio))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form (an infinite ratio is written as null)."""
        return {
            "task_names": self.task_names,
            "success": self.success,
            "own_error": self.own_error,
            "own_error_succeeded": self.own_error_succeeded,
            "own_error_failed": self.own_error_failed,
            "expert_error": self.expert_error,
            "own_error_by_dimension": self.own_error_by_dimension,
            "expert_error_by_dimension": self.expert_error_by_dimension,
            "ratio": [value if math.isfinite(value) else None for value in self.ratio],
            "mean_ratio": self.mean_ratio if math.isfinite(self.mean_ratio) else None,
            "median_ratio": self.median_ratio if math.isfinite(self.median_ratio) else None,
            "episodes": self.episodes,
            "seed": self.seed,
        }


def shift_ratio(own: float, expert: float) -> float:
    """``own / expert``; 1.0 when both are 0 (no error anywhere), inf when only ``expert`` is 0."""
    if expert > 0.0:
        return own / expert
    return 1.0 if own == 0.0 else math.inf


def measure_shift(workers: EnvWorkers, policy: PolicyFn, episodes_per_task: int, seed: int) -> ShiftResult:
    """Measures a policy's action error on its own states and on the expert's, per task.

    Args:
        workers: The env workers (their suite gives the tasks and the experts).
        policy: The policy (``PolicyRunner`` or any callable of observations and task names).
        episodes_per_task: Episodes per task (> 0), run once by the policy and once by the expert.
        seed: Seed of the evaluation episodes (``evaluate``'s episodes for the same seed).
    """
    if episodes_per_task <= 0:
        raise ValueError(f"episodes_per_task must be > 0, got {episodes_per_task}.")
    task_names = list(workers.suite.task_names)
    counts = [episodes_per_task] * len(task_names)
    own = _labelled_rollouts(workers, counts, policy, seed)
    expert = _labelled_rollouts(workers, counts, None, seed)
    bounds = action_bounds(workers.suite)
    own_errors = _episode_errors(policy, own, task_names, bounds)
    expert_errors = _episode_errors(policy, expert, task_names, bounds)
    rates, _ = success_by_task(own, len(task_names))
    tasks = range(len(task_names))
    own_by_dimension = [_every_episode_mean(own_errors, own, task) for task in tasks]
    expert_by_dimension = [_every_episode_mean(expert_errors, expert, task) for task in tasks]
    return ShiftResult(
        task_names=task_names,
        success=[rate if rate is not None else 0.0 for rate in rates],
        own_error=[float(mean.sum()) for mean in own_by_dimension],
        own_error_succeeded=[_total(_task_mean(own_errors, own, task, success=True)) for task in tasks],
        own_error_failed=[_total(_task_mean(own_errors, own, task, success=False)) for task in tasks],
        expert_error=[float(mean.sum()) for mean in expert_by_dimension],
        own_error_by_dimension=[mean.tolist() for mean in own_by_dimension],
        expert_error_by_dimension=[mean.tolist() for mean in expert_by_dimension],
        episodes=episodes_per_task,
        seed=seed,
    )


def action_bounds(suite: TaskSuite) -> tuple[np.ndarray, np.ndarray]:
    """The (low, high) of the suite's action space, from its first task's env (ValueError if not a box)."""
    env = suite.make_env(suite.task_names[0])
    try:
        space = env.action_space
        if not isinstance(space, gym.spaces.Box):
            raise ValueError(f"Suite {suite.name!r} has a {type(space).__name__} action space, not a Box.")
        return np.asarray(space.low, dtype=np.float64), np.asarray(space.high, dtype=np.float64)
    finally:
        env.close()


def _labelled_rollouts(
    workers: EnvWorkers, counts: Sequence[int], policy: PolicyFn | None, seed: int
) -> list[Episode]:
    """Recorded evaluation episodes with the expert's label at every state; the expert acts if no policy."""
    options = EpisodeOptions(
        beta=1.0 if policy is None else 0.0,
        seed=seed,
        round_index=0,
        stream=EVAL_STREAM,
        record=True,
        max_steps=None,
        steps_after_success=0,
    )
    return run_episodes(workers, counts, options, policy=policy)


def _episode_errors(
    policy: PolicyFn,
    episodes: Sequence[Episode],
    task_names: list[str],
    bounds: tuple[np.ndarray, np.ndarray],
) -> list[np.ndarray]:
    """``(clip(pi(s)) - label)^2`` per frame and dimension of each episode (one policy call per episode)."""
    errors = []
    for episode in episodes:
        frames = episode.frames
        tasks = [task_names[episode.task_index]] * len(frames)
        predicted = np.clip(np.asarray(policy(frames, tasks), dtype=np.float64), *bounds)
        labels = np.stack([np.asarray(frame["action"], dtype=np.float64) for frame in frames])
        errors.append((predicted - labels) ** 2)
    return errors


def _task_mean(
    errors: Sequence[np.ndarray], episodes: Sequence[Episode], task: int, success: bool | None = None
) -> np.ndarray | None:
    """Mean error per dimension over a task's episodes (with ``success`` if given; None without one)."""
    chosen = [
        error
        for error, episode in zip(errors, episodes, strict=True)
        if episode.task_index == task and (success is None or episode.success == success)
    ]
    return np.concatenate(chosen).mean(axis=0) if chosen else None


def _every_episode_mean(errors: Sequence[np.ndarray], episodes: Sequence[Episode], task: int) -> np.ndarray:
    """Mean error per frame and dimension over all of a task's episodes (every task has some)."""
    mean = _task_mean(errors, episodes, task)
    if mean is None:
        raise ValueError(f"No episode of task {task} was measured.")
    return mean


def _total(per_dimension: np.ndarray | None) -> float | None:
    """The squared error summed over action dimensions (None stays None)."""
    return None if per_dimension is None else float(per_dimension.sum())
