"""``lerobot-mtdagger verify``: every committed round and policy checked against its files and record."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lerobot_mtdagger.runner.configs import RunConfig


@dataclass
class VerifyConfig:
    """Options of ``lerobot-mtdagger verify``.

    Attributes:
        experiment_dir: The experiment's output directory.
    """

    experiment_dir: Path | None = None

    def __post_init__(self) -> None:
        if self.experiment_dir is None:
            raise ValueError("--experiment_dir is required (the output_dir of a run).")


def verify_command(config: VerifyConfig) -> list[str]:
    """Checks every committed round and policy against its files and record; exits 1 on a problem."""
    from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
    from lerobot_mtdagger.datasets.verify import verify_experiment

    experiment = ExperimentDir(config.experiment_dir)
    num_rounds, num_policies, problems = verify_experiment(experiment, RunConfig.option_defaults())
    note = experiment.ledger_note()
    if note is not None:
        print(f"NOTE {note}")
    for problem in problems:
        print(f"PROBLEM {problem}")
    print(
        f"verified {num_rounds} round(s) and {num_policies} policy folder(s) in {config.experiment_dir}: "
        f"{len(problems)} problem(s)"
    )
    if problems:
        raise SystemExit(1)
    return problems
