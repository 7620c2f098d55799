"""Rollouts with DAgger's beta-mixing, batched over tasks (Algorithm 1, "collect").

At every step of a DAgger rollout the expert labels the state; with probability ``beta`` the
EXPERT's action is executed, otherwise the learner's. The expert's label is always stored as
``action``; the executed action and whether the learner acted are stored beside it. ``beta = 1`` is
pure expert demonstration (round 0, BC); evaluation runs the pure policy (``beta = 0``, no expert).

One env per task is stepped in lock-step with the other tasks' envs, so the policy is queried once
per step for all active tasks (a batch-1 torch call costs ~0.1-1 ms). Episodes of a task run one
after another in that task's env. Every episode has its own seed, derived from
``(seed, stream, round, task, episode)``: collection seeds lie in [0, 2^31) and evaluation seeds in
[2^31, 2^32), so they never overlap, and evaluation uses the same seeds after every round.

An episode ends ``steps_after_success`` steps after its first success (MetaWorld's success does not
persist), at ``max_steps``, or when the env truncates.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.records import dagger_columns

logger = logging.getLogger(__name__)

COLLECT_STREAM = 0
EVAL_STREAM = 1
BETA_STREAM = 2

PolicyFn = Callable[[list[dict[str, np.ndarray]], list[str]], np.ndarray]
"""Maps a batch of observations and their task names to actions, (B, action_dim)."""


def episode_seed(seed: int, stream: int, round_index: int, task_index: int, episode: int) -> int:
    """Reset seed of one episode; collection and evaluation seeds lie in disjoint ranges."""
    value = int(np.random.SeedSequence([seed, stream, round_index, task_index, episode]).generate_state(1)[0])
    value %= 2**31
    return value + (2**31 if stream == EVAL_STREAM else 0)


@dataclass
class Episode:
    """One finished rollout.

    Attributes:
        task_index: Index of the task in the suite.
        episode: Index of the episode within its task and round.
        seed: Reset seed.
        success: Whether ``info["success"]`` was true at any step.
        frames: Recorded frames (empty when not recording).
        learner_steps: Steps where the learner's action was executed.
        steps: Episode length.
    """

    task_index: int
    episode: int
    seed: int
    success: bool = False
    frames: list[dict[str, Any]] = field(default_factory=list)
    learner_steps: int = 0
    steps: int = 0


@dataclass
class _Slot:
    """The episode currently running in one task's env."""

    task_index: int
    env: Any
    expert: Any
    queue: list[int]
    episode: Episode | None = None
    observation: dict[str, np.ndarray] | None = None
    privileged: np.ndarray | None = None
    steps_since_success: int = -1
    rng: np.random.Generator | None = None


def run_episodes(
    suite: TaskSuite,
    envs: Sequence[Any],
    episodes_per_task: Sequence[int],
    *,
    policy: PolicyFn | None,
    beta: float,
    seed: int,
    round_index: int,
    stream: int,
    record: bool,
    max_steps: int,
    steps_after_success: int,
    progress: Callable[[Episode], None] | None = None,
) -> list[Episode]:
    """Runs ``episodes_per_task[i]`` episodes of task i in ``envs[i]``, all tasks in lock-step.

    Args:
        suite: The suite (experts, task names).
        envs: One env per task of the suite, in task order (reused across episodes).
        episodes_per_task: Episodes to run per task.
        policy: The learner (None only when ``beta == 1``).
        beta: Probability of executing the expert's action at a step.
        seed: Experiment seed.
        round_index: DAgger round (part of the episode seeds).
        stream: ``COLLECT_STREAM`` or ``EVAL_STREAM``.
        record: Keep the frames (observation, expert label, executed action, learner flag).
        max_steps: Longest episode.
        steps_after_success: Steps kept after the first success.
        progress: Called with each finished episode.

    Returns:
        The episodes, ordered by (task, episode).

    Raises:
        ValueError: If ``policy`` is None while ``beta < 1``.
    """
    if policy is None and beta < 1.0:
        raise ValueError(f"beta={beta} < 1 needs a learner policy.")
    need_expert = record or beta > 0.0
    slots = []
    for task_index, (env, count) in enumerate(zip(envs, episodes_per_task, strict=True)):
        expert = make_expert(suite, suite.task_names[task_index]) if need_expert else None
        slots.append(_Slot(task_index, env, expert, queue=list(range(int(count)))))
    finished: list[Episode] = []
    for slot in slots:
        _start_next(slot, seed, round_index, stream)
    while any(slot.episode is not None for slot in slots):
        active = [slot for slot in slots if slot.episode is not None]
        learner_actions = _learner_actions(policy, active, suite, beta)
        for position, slot in enumerate(active):
            done = _step(
                slot, learner_actions, position, beta, round_index, record, max_steps, steps_after_success
            )
            if done:
                finished.append(slot.episode)
                if progress is not None:
                    progress(slot.episode)
                slot.episode = None
                _start_next(slot, seed, round_index, stream)
    finished.sort(key=lambda e: (e.task_index, e.episode))
    return finished


def _start_next(slot: _Slot, seed: int, round_index: int, stream: int) -> None:
    if not slot.queue:
        return
    episode_index = slot.queue.pop(0)
    reset_seed = episode_seed(seed, stream, round_index, slot.task_index, episode_index)
    slot.observation, info = slot.env.reset(seed=reset_seed)
    slot.privileged = info["privileged_state"]
    slot.episode = Episode(task_index=slot.task_index, episode=episode_index, seed=reset_seed)
    slot.steps_since_success = -1
    slot.rng = np.random.default_rng(
        np.random.SeedSequence([seed, BETA_STREAM, round_index, slot.task_index, episode_index])
    )
    if slot.expert is not None:
        slot.expert.reset()


def _learner_actions(
    policy: PolicyFn | None, active: list[_Slot], suite: TaskSuite, beta: float
) -> np.ndarray | None:
    if policy is None or beta >= 1.0:
        return None
    observations = [slot.observation for slot in active]
    tasks = [suite.task_names[slot.task_index] for slot in active]
    return np.asarray(policy(observations, tasks), dtype=np.float32)


def _step(
    slot: _Slot,
    learner_actions: np.ndarray | None,
    position: int,
    beta: float,
    round_index: int,
    record: bool,
    max_steps: int,
    steps_after_success: int,
) -> bool:
    """Steps one slot; returns whether its episode ended."""
    episode = slot.episode
    expert_action = slot.expert.act(slot.privileged) if slot.expert is not None else None
    expert_acts = learner_actions is None or (beta > 0.0 and slot.rng.random() < beta)
    executed = expert_action if expert_acts else learner_actions[position]
    if record:
        columns = dagger_columns(executed, learner_acted=not expert_acts, round_index=round_index)
        episode.frames.append({**slot.observation, "action": expert_action, **columns})
    slot.observation, _, terminated, truncated, info = slot.env.step(executed)
    slot.privileged = info["privileged_state"]
    episode.steps += 1
    episode.learner_steps += int(not expert_acts)
    if info["success"] and not episode.success:
        episode.success = True
        slot.steps_since_success = 0
    elif episode.success:
        slot.steps_since_success += 1
    return (
        terminated
        or truncated
        or episode.steps >= max_steps
        or (episode.success and slot.steps_since_success >= steps_after_success)
    )


def success_by_task(episodes: Sequence[Episode], num_tasks: int) -> tuple[list[float | None], list[int]]:
    """Raw success rate and episode count per task (None where a task had no episode)."""
    counts = [0] * num_tasks
    successes = [0] * num_tasks
    for episode in episodes:
        counts[episode.task_index] += 1
        successes[episode.task_index] += int(episode.success)
    rates = [successes[i] / counts[i] if counts[i] else None for i in range(num_tasks)]
    return rates, counts
