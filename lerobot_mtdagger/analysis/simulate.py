"""Synthetic multitask learning curves for exercising schedulers without simulators.

A task of hidden difficulty ``d`` succeeds with probability ``1 - exp(-n / d)`` after ``n`` expert
episodes; a round rolls out binomially and reports a loss drop that shrinks as the task saturates.
A toy for demos and scheduler tests, not a model of any benchmark.
"""

from __future__ import annotations

import dataclasses
import logging
from dataclasses import dataclass

import numpy as np

from lerobot_mtdagger.scheduler import Allocation, Scheduler

logger = logging.getLogger(__name__)


@dataclass
class SyntheticTasks:
    """Hidden learning curves: ``difficulty`` per task (> 0) and the ``demos`` collected so far."""

    difficulty: np.ndarray
    demos: np.ndarray

    @classmethod
    def spread(cls, num_tasks: int, easiest: float = 1.0, hardest: float = 30.0) -> SyntheticTasks:
        """Tasks with difficulties spread geometrically from ``easiest`` to ``hardest``."""
        if num_tasks < 1 or easiest <= 0 or hardest < easiest:
            raise ValueError(
                f"Need num_tasks >= 1 and 0 < easiest <= hardest, got {num_tasks}, {easiest}, {hardest}."
            )
        difficulty = np.geomspace(easiest, hardest, num_tasks)
        return cls(difficulty=difficulty, demos=np.zeros(num_tasks, dtype=np.int64))

    def success_probability(self) -> np.ndarray:
        """True success probability per task given the demos so far."""
        return 1.0 - np.exp(-self.demos / self.difficulty)

    def add_demos(self, episodes_per_task: np.ndarray) -> None:
        """Adds a round's expert episodes."""
        self.demos = self.demos + np.asarray(episodes_per_task, dtype=np.int64)

    def rollout(self, episodes_per_task: np.ndarray, rng: np.random.Generator) -> np.ndarray:
        """Measured success rate per task over ``episodes_per_task`` rollouts (NaN where 0)."""
        counts = np.asarray(episodes_per_task, dtype=np.int64)
        successes = rng.binomial(counts, self.success_probability())
        with np.errstate(invalid="ignore", divide="ignore"):
            return np.where(counts > 0, successes / np.maximum(counts, 1), np.nan)

    def loss_drop(self) -> np.ndarray:
        """A training round's loss drop per task: large while the task is far from saturated."""
        return (1.0 - self.success_probability()) / self.difficulty


@dataclass
class SimulatedRound:
    """One simulated DAgger round."""

    round: int
    allocation: Allocation
    true_success: list[float]
    demos_per_task: list[int]

    def to_dict(self) -> dict:
        """JSON-ready form."""
        return dataclasses.asdict(self) | {"allocation": self.allocation.to_dict()}


def simulate(
    scheduler: Scheduler, tasks: SyntheticTasks, rounds: int, budget: int, initial_demos: int, seed: int
) -> list[SimulatedRound]:
    """Runs the scheduling loop of Algorithm 1 on synthetic tasks; returns one record per round after 0.

    Round 0 gives every task ``initial_demos``; each later round feeds the scheduler the previous round's
    measured success and this round's loss drop, then allocates ``budget`` episodes (``tasks`` mutated).
    """
    rng = np.random.default_rng(seed)
    num_tasks = tasks.difficulty.size
    tasks.add_demos(np.full(num_tasks, initial_demos))
    history: list[SimulatedRound] = []
    previous: np.ndarray | None = None
    for round_index in range(1, rounds + 1):
        gain = tasks.loss_drop()
        if previous is None:
            scheduler.update(gain=gain)
        else:
            scheduler.update(success_rate=tasks.rollout(previous, rng), episodes=previous, gain=gain)
        allocation = scheduler.allocate(budget)
        counts = np.asarray(allocation.episodes_per_task)
        tasks.add_demos(counts)
        previous = counts
        history.append(
            SimulatedRound(
                round=round_index,
                allocation=allocation,
                true_success=tasks.success_probability().tolist(),
                demos_per_task=tasks.demos.tolist(),
            )
        )
        logger.debug("round %d allocation %s", round_index, allocation.episodes_per_task)
    return history
