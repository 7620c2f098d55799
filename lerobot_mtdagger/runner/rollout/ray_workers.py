"""Env workers as Ray actors (``--rollout.worker_backend=ray``): a run's simulators on a Ray cluster.

Each worker is a Ray actor running the same ``RolloutWorker``, one CPU each, spread over the nodes;
results do not depend on the backend. The suite travels pickled, but an expert registered in the
main process does not: give it with ``suite.with_experts(...)`` or register it where actors import.
"""

from __future__ import annotations

import logging
import os
import socket
from collections import deque
from typing import Any

from lerobot_mtdagger.envs.base import TaskSuite
from lerobot_mtdagger.runner.rollout.rollout_worker import RolloutWorker
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers, WorkerDiedError, answer, reply_payload
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.ray_session import connect

logger = logging.getLogger(__name__)

ACTOR_START_TIMEOUT_S = 300.0
"""Seconds the actors of a pool may take to be placed and to build their envs."""


class RolloutActor:
    """A ``RolloutWorker`` in a Ray actor (the class is wrapped by ``ray.remote`` on first use)."""

    def __init__(self, suite: TaskSuite) -> None:
        """Holds the suite's envs on this actor (one torch thread: the policy runs in the main process)."""
        import torch

        torch.set_num_threads(1)
        self.worker = RolloutWorker(suite)

    def where(self) -> str:
        """``host (node <id>):pid`` of this actor's process."""
        import ray

        node = ray.get_runtime_context().get_node_id()[:8]
        return f"{socket.gethostname()} (node {node}):{os.getpid()}"

    def handle(self, command: tuple[str, Any]) -> tuple[str, Any]:
        """The worker's ``answer`` to one command."""
        return answer(self.worker, command)

    def close(self) -> None:
        """Closes every env."""
        self.worker.close()


class _ActorConnection:
    """One actor seen as a pipe: ``send`` submits a command, ``recv`` waits for the oldest reply."""

    def __init__(self, ray: Any, actor: Any) -> None:
        self.ray = ray
        self.actor = actor
        self.pending: deque[Any] = deque()

    def send(self, command: tuple[str, Any]) -> None:
        self.pending.append(self.actor.handle.remote(command))

    def recv(self) -> tuple[str, Any]:
        return self.ray.get(self.pending.popleft())


class RayEnvWorkers(EnvWorkers):
    """``EnvWorkers`` whose ``workers`` are Ray actors on the cluster at ``address`` (None: local Ray)."""

    def __init__(
        self, suite: TaskSuite, workers: int, address: str | None = None, reserve_cpus: bool = True
    ) -> None:
        """Starts ``workers`` actors (at least one) and waits until each holds the suite.

        ``reserve_cpus=False`` reserves no CPU (a pool that runs only while the run's own actors wait).

        Raises:
            UserError: If Ray is missing, there is no cluster at ``address``, or the actors cannot be
                placed within ``ACTOR_START_TIMEOUT_S``.
        """
        self._ray = connect(address)
        self._places: list[str] = []
        self._cpus_per_actor = 1 if reserve_cpus else 0
        super().__init__(suite, max(workers, 1))

    def _start_processes(self, workers: int) -> None:
        ray = self._ray
        actor_class = ray.remote(num_cpus=self._cpus_per_actor, max_restarts=0, scheduling_strategy="SPREAD")(
            RolloutActor
        )
        suite = ray.put(self.suite)
        actors = [actor_class.remote(suite) for _ in range(workers)]
        try:
            self._places = ray.get([actor.where.remote() for actor in actors], timeout=ACTOR_START_TIMEOUT_S)
        except ray.exceptions.GetTimeoutError:
            for actor in actors:
                ray.kill(actor)  # never placed later behind the run's back
            raise self._not_placed(workers) from None
        self._processes = actors
        self._connections = [_ActorConnection(ray, actor) for actor in actors]
        logger.info("started %d env worker actors: %s", workers, self._places)

    def _not_placed(self, workers: int) -> UserError:
        """The error for ``workers`` actors that Ray could not place in time."""
        ray = self._ray
        total, free = ray.cluster_resources().get("CPU", 0), ray.available_resources().get("CPU", 0)
        return UserError(
            f"Ray could not place all {workers} env worker actors ({self._cpus_per_actor} CPU each) "
            f"within {ACTOR_START_TIMEOUT_S:g} s: the cluster has {total:g} CPUs, {free:g} free. Lower "
            "--rollout.workers, add nodes, or end what holds the CPUs (`ray status` lists them)."
        )

    def _receive(self, index: int) -> Any:
        """The reply of actor ``index``.

        Raises:
            WorkerDiedError: If the actor (or its node) is gone.
            Exception: The worker's own exception, with its traceback as the cause.
        """
        exceptions = self._ray.exceptions
        try:
            reply = self._connections[index].recv()
        except (exceptions.RayActorError, exceptions.ObjectLostError) as error:
            raise self._died(index) from error
        return reply_payload(reply)

    def _died(self, index: int) -> WorkerDiedError:
        """The error for actor ``index`` having gone without answering."""
        return WorkerDiedError(
            f"Env worker {index} (Ray actor on {self._places[index]}) died (killed, out of memory, or "
            "its node was lost); nothing of the running round was committed. Rerun with --resume=true "
            "to continue from the last committed round."
        )

    def close(self) -> None:
        """Closes every actor's envs and ends the actors."""
        ray = self._ray
        closing = []
        for actor in self._processes:
            try:
                closing.append(actor.close.remote())
            except ray.exceptions.RayActorError:
                logger.debug("env worker actor already gone")
        if closing:
            ray.wait(closing, num_returns=len(closing), timeout=10.0)
        for actor in self._processes:
            ray.kill(actor)
        self._processes.clear()
        self._connections.clear()


def make_env_workers(
    suite: TaskSuite,
    workers: int,
    backend: str = "local",
    address: str | None = None,
    reserve_cpus: bool = True,
) -> EnvWorkers:
    """The env workers of a run on ``backend`` (``local`` or ``ray``; ``reserve_cpus``: Ray only)."""
    if backend == "ray":
        return RayEnvWorkers(suite, workers, address, reserve_cpus)
    return EnvWorkers(suite, workers)
