"""The ``lerobot-mtdagger`` command.

Usage: ``lerobot-mtdagger <command> [--option=value ...]``. Options are parsed by draccus, so nested
configs are set with dots, for example ``--scheduler.type=need --scheduler.temperature=0.5``.

Commands:
    demo: run the performance-aware scheduler on synthetic tasks and print each round's allocation
        (no simulator, no policy; shows how the methods split a budget).
"""

from __future__ import annotations

import json
import logging
import sys
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path

import draccus
import numpy as np

from lerobot_mtdagger.scheduler import NeedSchedulerConfig, SchedulerConfig, scheduler_from_config
from lerobot_mtdagger.simulate import SyntheticTasks, simulate

logger = logging.getLogger(__name__)


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
    scheduler = scheduler_from_config(config.scheduler, config.num_tasks)
    tasks = SyntheticTasks.spread(config.num_tasks)
    history = simulate(scheduler, tasks, config.rounds, config.budget, config.initial_demos, config.seed)
    print(
        f"scheduler={config.scheduler.type} tasks={config.num_tasks} budget={config.budget}/round "
        f"T={config.scheduler.temperature} n_min={config.scheduler.n_min}"
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


COMMANDS: dict[str, tuple[type, Callable]] = {"demo": (DemoConfig, run_demo)}


def _usage() -> str:
    names = ", ".join(COMMANDS)
    return f"usage: lerobot-mtdagger <command> [--option=value ...]\ncommands: {names}\n" + (__doc__ or "")


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the console script.

    Args:
        argv: Arguments after the program name; ``sys.argv[1:]`` when None.

    Returns:
        The process exit status.
    """
    args = list(sys.argv[1:] if argv is None else argv)
    if not args or args[0] in ("-h", "--help", "help"):
        print(_usage())
        return 0
    command, options = args[0], args[1:]
    if command not in COMMANDS:
        print(f"unknown command {command!r}\n{_usage()}", file=sys.stderr)
        return 2
    logging.basicConfig(level=logging.INFO, format="%(asctime)s %(levelname)s %(name)s: %(message)s")
    config_class, function = COMMANDS[command]
    try:
        config = draccus.parse(config_class=config_class, args=options, prog=f"lerobot-mtdagger {command}")
    except draccus.utils.ParsingError as error:
        # draccus hides the config's own ValueError (which names the field and the fix) as the cause.
        cause = error.__cause__ if error.__cause__ is not None else error
        print(f"lerobot-mtdagger {command}: error: {cause}", file=sys.stderr)
        return 2
    function(config)
    return 0


if __name__ == "__main__":
    sys.exit(main())
