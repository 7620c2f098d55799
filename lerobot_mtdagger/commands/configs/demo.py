"""Options of ``lerobot-mtdagger demo``: the scheduler, the synthetic tasks and the rounds."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lerobot_mtdagger.scheduler import NeedSchedulerConfig, SchedulerConfig


@dataclass
class DemoConfig:
    """Options of ``lerobot-mtdagger demo``.

    Attributes:
        scheduler: Scheduling method and its hyperparameters (``--scheduler.type=need|gain|...``).
        num_tasks: Number of synthetic tasks, difficulties spread from easy to hard.
        rounds: DAgger rounds after round 0.
        budget: Episodes per round; 0 means 3 per task (the paper's MetaWorld state setting).
        initial_demos: Round-0 expert episodes per task.
        seed: Seed of the simulated rollout noise.
        output: Optional path of a JSON file receiving every round's full allocation record.
    """

    scheduler: SchedulerConfig = field(default_factory=NeedSchedulerConfig)
    num_tasks: int = 10
    rounds: int = 6
    budget: int = 0
    initial_demos: int = 3
    seed: int = 0
    output: Path | None = None

    def __post_init__(self) -> None:
        if self.num_tasks < 1:
            raise ValueError(f"num_tasks must be >= 1, got {self.num_tasks}.")
        if self.rounds < 1:
            raise ValueError(f"rounds must be >= 1, got {self.rounds}.")
        if self.budget == 0:
            self.budget = 3 * self.num_tasks
