"""Env workers: the simulators of a run stepped in worker processes, one per core by default.

A ``RolloutWorker`` owns envs and experts and runs each episode of a rollout (reset, the expert's
label, the env step, recording) by the DAgger mixing rules of ``lerobot_mtdagger.runner.mixing`` (who acts,
when an episode ends). The main process
keeps the policy and talks to the workers (see ``collect.run_episodes``): one message per worker
per step of a group of episodes, carrying the learner's actions for that worker's episodes and the episodes to
start, one reply carrying the new observations and the finished episodes.

``EnvWorkers(suite, workers=0)`` runs the worker in the calling process (no IPC); ``workers=N >= 1``
forks N processes that live until ``close``. Everything an episode does depends only on its seeds
and on the learner's actions, never on which worker ran it or on which env of that worker's pool it
reused, so the worker count never changes a result.

A worker that dies (killed, out of memory) is noticed on the next reply and raises
``WorkerDiedError`` in the main process; an exception inside a worker is sent back and re-raised
in the main process with the worker's traceback. Workers exit when the main process goes away
(their pipe closes), so a killed run leaves no orphan.
"""

from __future__ import annotations

import contextlib
import copy
import logging
import multiprocessing
import pickle
import signal
import sys
import traceback
from collections import defaultdict
from collections.abc import Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from typing import Any

import numpy as np

from lerobot_mtdagger.datasets.records import StepOutcome, dagger_columns
from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.experts.noise import ActionNoise
from lerobot_mtdagger.runner.mixing import (
    RolloutRules,
    episode_ends,
    expert_acts_now,
    expert_episode_coin,
    step_limit,
)

logger = logging.getLogger(__name__)


@contextlib.contextmanager
def limited_torch_threads(threads: int | None) -> Iterator[None]:
    """Caps torch's intra-op threads inside the block (no-op for None or when torch is not loaded).

    While the env workers keep every core busy, the main process's policy calls would only fight
    them for the cores.
    """
    torch = sys.modules.get("torch")
    if threads is None or torch is None:
        yield
        return
    previous = torch.get_num_threads()
    torch.set_num_threads(threads)
    try:
        yield
    finally:
        torch.set_num_threads(previous)


class WorkerDiedError(RuntimeError):
    """An env worker process ended without answering."""


class RemoteWorkerError(Exception):
    """The traceback of an exception raised inside a worker (attached as ``__cause__``)."""

    def __init__(self, text: str) -> None:
        """Keeps the formatted traceback."""
        super().__init__(text)
        self.text = text

    def __str__(self) -> str:
        return f"\n\nTraceback in the env worker:\n{self.text}"


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
        progress: Best ``info["progress"]`` of the episode (suites that report a progress score).
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
        handle: The main process's id of the running episode (unique while it runs).
        task_index: Task of the episode.
        episode: Index of the episode within its task and round.
        reset_seed: Seed of the env reset.
        beta_seed: Entropy of the episode's beta coin (expert or learner at each step).
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
        """Steps the episodes in ``actions``, then starts ``starts``.

        Without a learner (``rules.learner`` false: the expert acts at every step) nothing depends
        on the main process, so a started episode runs to its end here, in this one message.

        Args:
            starts: Episodes to start (their first observation is returned).
            actions: Learner action per running episode handle (None: no learner this call).

        Returns:
            The observation of every episode still running that was stepped or started, and the
            finished episodes by handle.
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
            if not self.rules.learner:
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
        env = pool.pop() if pool else self.suite.make_env(task_name)
        expert = self._expert(spec.task_index) if self.rules.need_expert else None
        expert_episode = self.rules.mixing == "episode" and expert_episode_coin(
            spec.beta_seed, self.rules.beta
        )
        max_steps = self.rules.max_steps
        if self.rules.expert_multiple is not None and self.rules.learner and not expert_episode:
            max_steps = self._expert_step_limit(env, expert, spec.reset_seed)
        observation, info = env.reset(seed=spec.reset_seed)
        rng = np.random.default_rng(np.random.SeedSequence(list(spec.beta_seed)))
        noise = None
        if expert is not None and self.suite.expert_noise is not None:
            key = (self.rules.round_index, spec.task_index, spec.episode)
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
        """``max_steps`` capped at ``expert_multiple`` times the expert's own steps to success.

        Runs the expert's trial episode on ``env`` and resets ``expert`` after it.
        """
        expert_steps = _expert_steps_to_success(env, expert, reset_seed)
        expert.reset()
        return step_limit(self.rules, expert_steps)

    def _expert(self, task_index: int) -> Any:
        """A reset expert of the task that no running episode uses.

        The first one comes from ``make_expert``; more (for episodes of the same task running at
        once) are deep copies of it, so an expert given as an instance (``suite.with_experts``) is
        never shared by two episodes.
        """
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
        rules = self.rules
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
            columns = dagger_columns(executed, not expert_acts, rules.round_index, outcome)
            episode.frames.append({**observation, "action": label, **columns})
        return ended


def _expert_action(running: _Running) -> tuple[np.ndarray | None, np.ndarray | None]:
    """What the expert would execute at this step, and its label (both None without an expert).

    A perfect expert executes and labels its own action; an imperfect one (``suite.expert_noise``)
    executes its action plus this episode's noise, and labels the noisy or its own action
    (``ExpertNoise.labels``). The noise advances at every step the expert is queried, whoever acts.
    """
    if running.expert is None:
        return None, None
    action = running.expert.act(running.privileged)
    if running.noise is None:
        return action, action
    return running.noise.perturb(action)


def _expert_steps_to_success(env: Any, expert: Any, reset_seed: int) -> int | None:
    """Steps the expert alone takes from ``reset_seed`` to its first success (None: it never succeeds).

    Runs one unrecorded expert episode on ``env`` (the caller resets ``env`` and ``expert`` after it).
    """
    _, info = env.reset(seed=reset_seed)
    steps = 0
    while True:
        _, _, terminated, truncated, info = env.step(expert.act(info["privileged_state"]))
        steps += 1
        if info["success"]:
            return steps
        if terminated or truncated:
            return None


def _worker_loop(connection: Connection, suite: TaskSuite, inherited: list[Connection]) -> None:
    """Body of a worker process: answers commands until told to close or the main process is gone.

    Args:
        connection: This worker's end of its pipe.
        suite: The suite (forked, so registered experts come along).
        inherited: The main process's ends of this and the earlier workers' pipes, closed here so each
            pipe closes when the main process dies.
    """
    for other in inherited:
        other.close()
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the main process's to handle
    if "torch" in sys.modules:
        sys.modules["torch"].set_num_threads(1)
    worker = RolloutWorker(suite)
    try:
        while True:
            try:
                command = connection.recv()
            except EOFError:
                return
            if command[0] == "close":
                return
            connection.send(answer(worker, command))
    finally:
        worker.close()


def answer(worker: RolloutWorker, command: tuple[str, Any]) -> tuple[str, Any]:
    """``("ok", reply)``, or ``("error", (exception, traceback text))`` to re-raise in the main process."""
    try:
        return "ok", worker.handle(command)
    except Exception as error:  # noqa: BLE001 - re-raised in the main process (``reply_payload``)
        return "error", (_picklable(error), traceback.format_exc())


def reply_payload(reply: tuple[str, Any]) -> Any:
    """The payload of a worker's ``answer``.

    Raises:
        Exception: The worker's own exception, with its traceback as the cause.
    """
    status, payload = reply
    if status == "error":
        error, text = payload
        raise error from RemoteWorkerError(text)
    return payload


def _picklable(error: Exception) -> Exception:
    """``error`` itself when it survives pickling, else a RuntimeError with its message."""
    try:
        pickle.loads(pickle.dumps(error))
    except (pickle.PicklingError, TypeError, AttributeError):
        return RuntimeError(f"{type(error).__name__}: {error}")
    return error


@dataclass
class Ticket:
    """The replies one ``EnvWorkers.send`` is owed.

    Attributes:
        busy: Workers that were sent a command.
        local_replies: The replies already computed in-process (``workers=0``).
    """

    busy: list[int]
    local_replies: list[Any] = field(default_factory=list)


class EnvWorkers:
    """The envs of a run, in ``workers`` processes (0: in the calling process).

    Use as a context manager, or call ``close``.
    """

    def __init__(self, suite: TaskSuite, workers: int) -> None:
        """Starts the worker processes (forked: they inherit the suite and registered experts).

        Raises:
            ValueError: If ``workers`` is negative.
        """
        if workers < 0:
            raise ValueError(f"workers must be >= 0 (0: in this process), got {workers}.")
        self.suite = suite
        self.workers = workers
        self._local = RolloutWorker(suite) if workers == 0 else None
        self._processes: list[Any] = []
        self._connections: list[Connection] = []
        if workers:
            self._start_processes(workers)

    @property
    def slots(self) -> int:
        """How many workers episodes are spread over (1 when in-process)."""
        return max(self.workers, 1)

    def _start_processes(self, workers: int) -> None:
        context = multiprocessing.get_context("fork")
        for index in range(workers):
            parent_end, child_end = context.Pipe()
            process = context.Process(
                target=_worker_loop,
                args=(child_end, self.suite, [*self._connections, parent_end]),
                name=f"mtdagger-env-worker-{index}",
                daemon=True,
            )
            process.start()
            child_end.close()
            self._processes.append(process)
            self._connections.append(parent_end)
        logger.debug("started %d env workers: %s", workers, [p.pid for p in self._processes])

    def set_rules(self, rules: RolloutRules) -> None:
        """Sets the rules of the episodes started from now on."""
        if self._local is not None:
            self._local.handle(("rules", rules))
            return
        for index in range(self.workers):
            self._connections[index].send(("rules", rules))
        for index in range(self.workers):
            self._receive(index)

    def send(self, commands: list[tuple[list[EpisodeSpec], dict[int, np.ndarray | None]]]) -> Ticket:
        """Sends each worker its (starts, actions); the ticket says whose replies to ``receive``."""
        busy = [index for index, (starts, actions) in enumerate(commands) if starts or actions]
        if self._local is not None:
            return Ticket(busy, [self._local.iterate(*commands[0])] if busy else [])
        for index in busy:
            try:
                self._connections[index].send(("iterate", commands[index]))
            except OSError as error:  # BrokenPipeError, ConnectionResetError: the worker is gone
                raise self._died(index) from error
        return Ticket(busy)

    def receive(
        self, ticket: Ticket | None
    ) -> list[tuple[dict[int, dict[str, np.ndarray]], list[tuple[int, Episode]]]]:
        """The replies owed for ``ticket`` (none for None), in worker order."""
        if ticket is None:
            return []
        if self._local is not None:
            return ticket.local_replies
        return [self._receive(index) for index in ticket.busy]

    def _receive(self, index: int) -> Any:
        """The reply of worker ``index``.

        Raises:
            WorkerDiedError: If the worker process ended.
            Exception: The worker's own exception, with its traceback as the cause.
        """
        connection, process = self._connections[index], self._processes[index]
        if connection not in wait([connection, process.sentinel]):
            raise self._died(index)
        try:
            reply = connection.recv()
        except (EOFError, OSError) as error:
            raise self._died(index) from error
        return reply_payload(reply)

    def _died(self, index: int) -> WorkerDiedError:
        """The error for worker ``index`` having ended without answering."""
        process = self._processes[index]
        process.join(timeout=1.0)
        return WorkerDiedError(
            f"Env worker {index} (pid {process.pid}) died with exit code {process.exitcode} "
            "(killed, or out of memory?); nothing of the running round was committed. Rerun "
            "with --resume=true to continue from the last committed round."
        )

    def close(self) -> None:
        """Stops the workers and closes every env."""
        if self._local is not None:
            self._local.close()
            return
        for connection in self._connections:
            try:
                connection.send(("close", None))
            except (BrokenPipeError, OSError):
                logger.debug("env worker pipe already closed")
        for process in self._processes:
            process.join(timeout=5.0)
            if process.is_alive():
                process.terminate()
                process.join(timeout=1.0)
        for connection in self._connections:
            connection.close()
        self._processes.clear()
        self._connections.clear()

    def __enter__(self) -> EnvWorkers:
        return self

    def __exit__(self, *exc_info: object) -> None:
        self.close()
