"""``lerobot-mtdagger demo``: the performance-aware scheduler on synthetic tasks, round by round.

No simulator and no policy: shows how the methods split a budget.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.simulate import SyntheticTasks, simulate
from lerobot_mtdagger.scheduler import NeedSchedulerConfig, Scheduler, SchedulerConfig


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


def run_demo(config: DemoConfig) -> list[dict]:
    """Runs the scheduler demo and prints one line per round.

    Args:
        config: The demo options.

    Returns:
        The JSON-ready round records.
    """
    scheduler = Scheduler(config.scheduler, config.num_tasks)
    tasks = SyntheticTasks.spread(config.num_tasks)
    history = simulate(scheduler, tasks, config.rounds, config.budget, config.initial_demos, config.seed)
    print(
        f"scheduler={config.scheduler.type} tasks={config.num_tasks} budget={config.budget}/round "
        f"T={config.scheduler.temperature} n_min={config.scheduler.min_episodes}"
    )
    print("task difficulty (easy -> hard):", np.round(tasks.difficulty, 1).tolist())
    for record in history:
        print(
            f"round {record.round}: allocation {record.allocation.episodes_per_task} "
            f"mean true success {np.mean(record.true_success):.3f}"
        )
    records = [record.to_dict() for record in history]
    if config.output is not None:
        config.output.parent.mkdir(parents=True, exist_ok=True)
        config.output.write_text(json.dumps(records, indent=2))
        print(f"wrote {config.output}")
    return records
