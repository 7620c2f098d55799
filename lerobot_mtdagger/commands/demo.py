"""``lerobot-mtdagger demo``: the performance-aware scheduler on synthetic tasks, round by round.

No simulator and no policy: shows how the methods split a budget. Its options are ``DemoConfig``
(``configs/demo.py``).
"""

from __future__ import annotations

import json

import numpy as np

from lerobot_mtdagger.analysis.simulate import SyntheticTasks, simulate
from lerobot_mtdagger.commands.configs.demo import DemoConfig
from lerobot_mtdagger.scheduler import Scheduler

__all__ = ["DemoConfig", "run_demo"]


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
