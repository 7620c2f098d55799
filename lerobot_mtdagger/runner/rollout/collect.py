"""Rollouts with DAgger's beta-mixing, batched over tasks (Algorithm 1, "collect").

The expert labels every state; with probability ``beta`` its action is executed (a coin per step or
per episode: ``mixing``). ``beta = 1`` is pure demonstration (round 0, BC); evaluation runs the pure
policy. The envs live in env workers; the policy, in the main process, is queried once per step for
every running episode. Episode seeds derive from ``(seed, stream, round, task, episode)``; collection
and evaluation seeds never overlap, and evaluation uses the same seeds every round.
"""

from __future__ import annotations

import logging
from collections import deque
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from typing import cast

import numpy as np

from lerobot_mtdagger.runner.rollout.mixing import RolloutRules
from lerobot_mtdagger.runner.rollout.workers import (
    EnvWorkers,
    Episode,
    EpisodeSpec,
    Ticket,
    limited_torch_threads,
)
from lerobot_mtdagger.utils.seeds import BETA_STREAM, EVAL_STREAM, stream_seed

logger = logging.getLogger(__name__)

LANE_GROUPS = 2

PolicyFn = Callable[[list[dict[str, np.ndarray]], list[str]], np.ndarray]
"""Maps a batch of observations and their task names to actions, (B, action_dim)."""


def episode_seed(seed: int, stream: int, round_index: int, task_index: int, episode: int) -> int:
    """Reset seed of one episode; collection and evaluation seeds lie in disjoint ranges."""
    value = stream_seed(seed, stream, round_index, task_index, episode)
    value %= 2**31
    return value + (2**31 if stream == EVAL_STREAM else 0)


@dataclass
class _Lane:
    """One of the episodes that run at the same time (one lane per task, see ``run_episodes``).

    Attributes:
        home_task: The task whose episodes the lane runs first.
        group: The learner acts for one group while the workers step the other.
        task_index: Task of the running episode (None: idle).
        worker: Worker running the episode.
        observation: Its latest observation (None until the worker has reset the env).
        start: The episode to start in the next message (None once started).
        fresh: Whether the learner has not yet acted in the running episode.
    """

    home_task: int
    group: int
    task_index: int | None = None
    worker: int = 0
    observation: dict[str, np.ndarray] | None = None
    start: EpisodeSpec | None = None
    fresh: bool = False


@dataclass
class _Schedule:
    """Which episode each lane runs next: its own task's first, then the task with most left."""

    queues: list[deque[int]]
    seed: int
    round_index: int
    stream: int

    def next_episode(self, lane: _Lane, handle: int) -> EpisodeSpec | None:
        """The next episode for ``lane`` (None when every queue is empty)."""
        task = lane.home_task
        if not self.queues[task]:
            remaining = [len(queue) for queue in self.queues]
            if max(remaining) == 0:
                return None
            task = int(np.argmax(remaining))  # ties: the lowest task index
        episode = self.queues[task].popleft()
        return EpisodeSpec(
            handle=handle,
            task_index=task,
            episode=episode,
            reset_seed=episode_seed(self.seed, self.stream, self.round_index, task, episode),
            beta_seed=(self.seed, BETA_STREAM, self.round_index, task, episode),
        )


@dataclass(frozen=True)
class EpisodeOptions:
    """How the episodes of one ``run_episodes`` call run: ``RolloutRules``' options, seeded.

    ``seed`` is the experiment's, ``stream`` ``COLLECT_STREAM`` or ``EVAL_STREAM``; the other fields are
    those of ``RolloutRules`` (``rules`` adds ``learner``).
    """

    beta: float
    seed: int
    round_index: int
    stream: int
    record: bool
    max_steps: int | None
    steps_after_success: int
    mixing: str = "step"
    expert_multiple: float | None = None

    def rules(self, learner: bool) -> RolloutRules:
        """The workers' rules for these episodes (``learner``: whether a learner acts at all)."""
        return RolloutRules(
            beta=self.beta,
            learner=learner,
            record=self.record,
            round_index=self.round_index,
            max_steps=self.max_steps,
            steps_after_success=self.steps_after_success,
            mixing=self.mixing,
            expert_multiple=self.expert_multiple,
        )


def run_episodes(
    workers: EnvWorkers,
    episodes_per_task: Sequence[int],
    options: EpisodeOptions,
    *,
    policy: PolicyFn | None,
    progress: Callable[[Episode], None] | None = None,
) -> list[Episode]:
    """Runs ``episodes_per_task[i]`` episodes of task i on the env workers; ordered by (task, episode).

    One lane per task runs its own task's episodes, then helps the task with most left. The lanes form
    two groups (even and odd tasks), pipelined: while the workers step one group, the main process runs
    the learner once for the other. Nothing depends on the number of workers. ``policy`` may be None
    only when ``options.beta == 1``; ``progress`` is called with each finished episode.

    Raises:
        ValueError: If ``policy`` is None while ``beta < 1``, or the counts do not match the tasks.
    """
    task_names = workers.suite.task_names
    if policy is None and options.beta < 1.0:
        raise ValueError(f"beta={options.beta} < 1 needs a learner policy.")
    if len(episodes_per_task) != len(task_names):
        raise ValueError(f"Got {len(episodes_per_task)} episode counts for {len(task_names)} tasks.")
    learner = policy is not None and options.beta < 1.0
    workers.set_rules(options.rules(learner))
    queues = [deque(range(int(n))) for n in episodes_per_task]
    schedule = _Schedule(queues, options.seed, options.round_index, options.stream)
    lanes = [_Lane(home_task=task, group=task % LANE_GROUPS) for task in range(len(task_names))]
    for handle in range(len(lanes)):
        _assign(lanes, handle, schedule, workers.slots)
    finished: list[Episode] = []
    outstanding: list[Ticket | None] = [None] * LANE_GROUPS
    with limited_torch_threads(1):
        while any(lane.task_index is not None for lane in lanes) or any(t is not None for t in outstanding):
            for group in range(LANE_GROUPS):
                for handle, episode in _receive(workers, outstanding[group], lanes):
                    finished.append(episode)
                    if progress is not None:
                        progress(episode)
                    _assign(lanes, handle, schedule, workers.slots)
                members = [handle for handle, lane in enumerate(lanes) if lane.group == group]
                actions = _learner_actions(policy if learner else None, lanes, members, task_names)
                commands = _commands(lanes, members, actions, workers.slots)
                outstanding[group] = workers.send(commands) if any(c[0] or c[1] for c in commands) else None
    finished.sort(key=lambda e: (e.task_index, e.episode))
    return finished


def _receive(workers: EnvWorkers, ticket: Ticket | None, lanes: list[_Lane]) -> list[tuple[int, Episode]]:
    """Takes the replies owed for ``ticket``; returns the finished episodes by lane."""
    done: list[tuple[int, Episode]] = []
    for observations, ended in workers.receive(ticket):
        for handle, observation in observations.items():
            lanes[handle].observation = observation
        done += ended
    return sorted(done, key=lambda item: item[0])


def _commands(
    lanes: list[_Lane], members: list[int], actions: dict[int, np.ndarray | None], worker_count: int
) -> list[tuple[list[EpisodeSpec], dict[int, np.ndarray | None]]]:
    """Per worker: the episodes of ``members`` to start and the actions of those to step."""
    commands: list[tuple[list[EpisodeSpec], dict[int, np.ndarray | None]]] = [
        ([], {}) for _ in range(worker_count)
    ]
    for handle in members:
        lane = lanes[handle]
        if lane.start is not None:
            commands[lane.worker][0].append(lane.start)
            lane.start = None
        elif handle in actions:
            commands[lane.worker][1][handle] = actions[handle]
            lane.observation = None  # consumed: the next one comes with the reply
    return commands


def _assign(lanes: list[_Lane], handle: int, schedule: _Schedule, worker_count: int) -> None:
    """Gives lane ``handle`` its next episode, on the least loaded worker (``_least_loaded``)."""
    lane = lanes[handle]
    lane.observation = None
    spec = schedule.next_episode(lane, handle)
    if spec is None:
        lane.task_index = None
        return
    lane.task_index, lane.worker, lane.start = spec.task_index, _least_loaded(lanes, lane, worker_count), spec
    lane.fresh = True


def _least_loaded(lanes: list[_Lane], lane: _Lane, worker_count: int) -> int:
    """The worker running the fewest of ``lane``'s group, then the fewest episodes in all.

    Each group's reply waits for its slowest worker, so its lanes are spread evenly, and every worker
    steps as many episodes per cycle of the two groups (``benchmarks/bench_collect.py``).
    """
    group_load = [0] * worker_count
    total_load = [0] * worker_count
    for other in lanes:
        if other.task_index is not None and other is not lane:
            total_load[other.worker] += 1
            group_load[other.worker] += int(other.group == lane.group)
    return min(range(worker_count), key=lambda worker: (group_load[worker], total_load[worker]))


def _learner_actions(
    policy: PolicyFn | None, lanes: list[_Lane], members: list[int], task_names: Sequence[str]
) -> dict[int, np.ndarray | None]:
    """The learner's action for each lane of ``members`` with an observation (None: no learner).

    A policy with ``tracks_episodes`` (``ChunkRunner``) also gets each row's lane and episode start.
    """
    ready = [handle for handle in members if lanes[handle].observation is not None]
    if policy is None or not ready:
        return dict.fromkeys(ready)
    # A lane with an observation runs an episode: its task_index is set.
    observations = cast("list[dict[str, np.ndarray]]", [lanes[handle].observation for handle in ready])
    tasks = [task_names[cast(int, lanes[handle].task_index)] for handle in ready]
    if getattr(policy, "tracks_episodes", False):
        tracking: Callable[..., np.ndarray] = policy  # also takes lanes= and starts=
        starts = [lanes[handle].fresh for handle in ready]
        actions = np.asarray(tracking(observations, tasks, lanes=ready, starts=starts), dtype=np.float32)
    else:
        actions = np.asarray(policy(observations, tasks), dtype=np.float32)
    for handle in ready:
        lanes[handle].fresh = False
    return {handle: actions[position] for position, handle in enumerate(ready)}


def success_by_task(episodes: Sequence[Episode], num_tasks: int) -> tuple[list[float | None], list[int]]:
    """Raw success rate and episode count per task (None where a task had no episode)."""
    counts = [0] * num_tasks
    successes = [0] * num_tasks
    for episode in episodes:
        counts[episode.task_index] += 1
        successes[episode.task_index] += int(episode.success)
    rates = [successes[i] / counts[i] if counts[i] else None for i in range(num_tasks)]
    return rates, counts


def learner_success_by_task(
    episodes: Sequence[Episode], num_tasks: int
) -> tuple[list[float | None], list[int]]:
    """Success rate and count per task of the episodes where only the learner acted (what task need reads)."""
    return success_by_task([episode for episode in episodes if episode.learner_only], num_tasks)
