"""A rollout worker: its envs and experts, and each episode it runs (reset, label, step, record).

An episode depends only on its seeds and the learner's actions, never on which worker ran it or
which env of its pool it reused.
"""

from __future__ import annotations

import copy
from collections import defaultdict
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from lerobot_mtdagger.datasets.records import StepOutcome, dagger_columns
from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.experts.noise import ActionNoise
from lerobot_mtdagger.runner.rollout.mixing import (
    RolloutRules,
    episode_ends,
    expert_acts_now,
    expert_episode_coin,
    step_limit,
)


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
        progress: Best ``info["progress"]`` of the episode (suites with a progress score).
    """

    task_index: int
    episode: int
    seed: int
    success: bool = False
    frames: list[dict[str, Any]] = field(default_factory=list)
    learner_steps: int = 0
    steps: int = 0
    progress: int = 0

    @property
    def learner_only(self) -> bool:
        """Whether the learner executed every action (its success is then the learner's)."""
        return self.steps > 0 and self.learner_steps == self.steps


@dataclass(frozen=True)
class EpisodeSpec:
    """What a worker needs to start an episode.

    Attributes:
        handle: The main process's id of the running episode.
        task_index: Task of the episode.
        episode: Index of the episode within its task and round.
        reset_seed: Seed of the env reset.
        beta_seed: Entropy of the episode's beta coin.
    """

    handle: int
    task_index: int
    episode: int
    reset_seed: int
    beta_seed: tuple[int, ...]


@dataclass
class _Running:
    """An episode running in one env of a worker."""

    spec: EpisodeSpec
    env: Any
    expert: Any
    episode: Episode
    rng: np.random.Generator
    observation: dict[str, np.ndarray]
    privileged: np.ndarray
    steps_since_success: int = -1
    expert_episode: bool = False
    max_steps: int | None = None
    noise: ActionNoise | None = None


class RolloutWorker:
    """The env side of rollouts: a pool of envs per task, their experts and the running episodes."""

    def __init__(self, suite: TaskSuite) -> None:
        """Holds no env until an episode of a task starts."""
        self.suite = suite
        self.free_envs: dict[int, list[Any]] = defaultdict(list)
        self.experts: dict[int, list[Any]] = defaultdict(list)
        self.first_experts: dict[int, Any] = {}
        self.running: dict[int, _Running] = {}
        self.rules: RolloutRules | None = None

    @property
    def _rules(self) -> RolloutRules:
        """The rules of the running episodes (the main process sends them before any episode)."""
        assert self.rules is not None, "the rules are set before any episode starts"
        return self.rules

    def handle(self, command: tuple[str, Any]) -> Any:
        """Executes one command of the main process and returns its reply."""
        name, payload = command
        if name == "rules":
            self.rules = payload
            return None
        if name == "iterate":
            starts, actions = payload
            return self.iterate(starts, actions)
        raise ValueError(f"Unknown worker command {name!r}.")

    def iterate(
        self, starts: list[EpisodeSpec], actions: dict[int, np.ndarray | None]
    ) -> tuple[dict[int, dict[str, np.ndarray]], list[tuple[int, Episode]]]:
        """Steps the episodes in ``actions`` (by handle; None: no learner), then starts ``starts``.

        Without a learner nothing depends on the main process, so a started episode runs to its end here.

        Returns:
            The observation of each episode still running that was stepped or started, and the finished
            episodes by handle.
        """
        observations: dict[int, dict[str, np.ndarray]] = {}
        finished: list[tuple[int, Episode]] = []
        for handle, action in actions.items():
            running = self.running[handle]
            if self._step(running, action):
                finished.append((handle, running.episode))
                self._release(self.running.pop(handle))
            else:
                observations[handle] = running.observation
        for spec in starts:
            running = self._start(spec)
            if not self._rules.learner:
                while not self._step(running, None):
                    pass
                finished.append((spec.handle, running.episode))
                self._release(running)
                continue
            self.running[spec.handle] = running
            observations[spec.handle] = running.observation
        return observations, finished

    def close(self) -> None:
        """Closes every env."""
        for envs in self.free_envs.values():
            for env in envs:
                env.close()
        for running in self.running.values():
            running.env.close()
        self.free_envs.clear()
        self.running.clear()

    def _start(self, spec: EpisodeSpec) -> _Running:
        task_name = self.suite.task_names[spec.task_index]
        pool = self.free_envs[spec.task_index]
        env: Any = pool.pop() if pool else self.suite.make_env(task_name)
        rules = self._rules
        expert = self._expert(spec.task_index) if rules.need_expert else None
        expert_episode = rules.mixing == "episode" and expert_episode_coin(spec.beta_seed, rules.beta)
        max_steps = rules.max_steps
        if rules.expert_multiple is not None and rules.learner and not expert_episode:
            max_steps = self._expert_step_limit(env, expert, spec.reset_seed)
        observation, info = env.reset(seed=spec.reset_seed)
        rng = np.random.default_rng(np.random.SeedSequence(list(spec.beta_seed)))
        noise = None
        if expert is not None and self.suite.expert_noise is not None:
            key = (rules.round_index, spec.task_index, spec.episode)
            bounds = (env.action_space.low, env.action_space.high)
            noise = self.suite.expert_noise.episode_process(key, *bounds, task=task_name)
        return _Running(
            spec=spec,
            env=env,
            expert=expert,
            episode=Episode(task_index=spec.task_index, episode=spec.episode, seed=spec.reset_seed),
            rng=rng,
            observation=observation,
            privileged=info["privileged_state"],
            expert_episode=expert_episode,
            max_steps=max_steps,
            noise=noise,
        )

    def _expert_step_limit(self, env: Any, expert: Any, reset_seed: int) -> int | None:
        """``max_steps`` capped at ``expert_multiple`` times the expert's steps to success on ``env``."""
        expert_steps = _expert_steps_to_success(env, expert, reset_seed)
        expert.reset()
        return step_limit(self._rules, expert_steps)

    def _expert(self, task_index: int) -> Any:
        """A reset expert of the task that no running episode uses (else a deep copy of the first)."""
        free = self.experts[task_index]
        if free:
            expert = free.pop()
        elif task_index not in self.first_experts:
            expert = self.first_experts[task_index] = make_expert(
                self.suite, self.suite.task_names[task_index]
            )
        else:
            expert = copy.deepcopy(self.first_experts[task_index])
        expert.reset()
        return expert

    def _release(self, running: _Running) -> None:
        self.free_envs[running.spec.task_index].append(running.env)
        if running.expert is not None:
            self.experts[running.spec.task_index].append(running.expert)

    def _step(self, running: _Running, learner_action: np.ndarray | None) -> bool:
        """Steps one episode; returns whether it ended."""
        rules = self._rules
        episode = running.episode
        expert_action, label = _expert_action(running)
        expert_acts = expert_acts_now(rules, learner_action is not None, running.expert_episode, running.rng)
        executed = expert_action if expert_acts else learner_action
        observation = running.observation
        running.observation, reward, terminated, truncated, info = running.env.step(executed)
        running.privileged = info["privileged_state"]
        episode.steps += 1
        episode.learner_steps += int(not expert_acts)
        episode.progress = max(episode.progress, int(info.get("progress", 0)))
        if info["success"] and not episode.success:
            episode.success = True
            running.steps_since_success = 0
        elif episode.success:
            running.steps_since_success += 1
        ended = bool(terminated or truncated) or episode_ends(
            rules, episode.steps, running.max_steps, running.steps_since_success
        )
        if rules.record:
            outcome = StepOutcome(reward=float(reward), success=bool(info["success"]), done=ended)
            assert executed is not None  # recording queries the expert, and the expert acts without a learner
            columns = dagger_columns(executed, not expert_acts, rules.round_index, outcome)
            episode.frames.append({**observation, "action": label, **columns})
        return ended


def _expert_action(running: _Running) -> tuple[np.ndarray | None, np.ndarray | None]:
    """What the expert would execute at this step, and its label (both None without an expert).

    An imperfect expert executes its action plus the episode's noise and labels by ``ExpertNoise.labels``;
    the noise advances at every step the expert is queried, whoever acts.
    """
    if running.expert is None:
        return None, None
    action = running.expert.act(running.privileged)
    if running.noise is None:
        return action, action
    return running.noise.perturb(action)


def _expert_steps_to_success(env: Any, expert: Any, reset_seed: int) -> int | None:
    """Steps the expert alone takes from ``reset_seed`` to its first success (None: never), unrecorded."""
    _, info = env.reset(seed=reset_seed)
    steps = 0
    while True:
        _, _, terminated, truncated, info = env.step(expert.act(info["privileged_state"]))
        steps += 1
        if info["success"]:
            return steps
        if terminated or truncated:
            return None
