"""Env workers: the simulators of a run stepped in worker processes, one per core by default.

The main process keeps the policy and sends each worker one message per step of a group of episodes;
``workers=0`` runs in-process. A worker's death or exception is raised in the main process.
"""

from __future__ import annotations

import contextlib
import logging
import multiprocessing
import pickle
import signal
import sys
import traceback
from collections.abc import Iterator
from dataclasses import dataclass, field
from multiprocessing.connection import Connection, wait
from typing import Any

import numpy as np

from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.runner.rollout.mixing import (
    RolloutRules,
)
from lerobot_mtdagger.runner.rollout.rollout_worker import Episode, EpisodeSpec, RolloutWorker

logger = logging.getLogger(__name__)


@contextlib.contextmanager
def limited_torch_threads(threads: int | None) -> Iterator[None]:
    """Caps torch's intra-op threads inside the block, so the policy leaves the cores to the env workers."""
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


def _worker_loop(connection: Connection, suite: TaskSuite, inherited: list[Connection]) -> None:
    """Body of a worker process: answers commands until told to close or the main process is gone.

    ``inherited`` are the main process's pipe ends, closed here so each pipe closes when it dies.
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
    """The payload of a worker's ``answer``; re-raises the worker's own exception with its traceback."""
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
    """The replies one ``EnvWorkers.send`` is owed: ``busy`` workers', or ``local_replies`` in-process."""

    busy: list[int]
    local_replies: list[Any] = field(default_factory=list)


class EnvWorkers:
    """The envs of a run, in ``workers`` processes (0: in the calling process); a context manager."""

    def __init__(self, suite: TaskSuite, workers: int) -> None:
        """Forks the worker processes (they inherit the suite and experts); ``ValueError`` if negative."""
        if workers < 0:
            raise ValueError(f"workers must be >= 0 (0: in this process), got {workers}.")
        self.suite = suite
        self.workers = workers
        self._local = RolloutWorker(suite) if workers == 0 else None
        self._processes: list[Any] = []
        self._connections: list[Any] = []  # pipe ends (Connection); Ray's: actors seen as pipes
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
