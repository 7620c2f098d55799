"""``lerobot-mtdagger verify``: every committed round and policy checked against its files and record.

Its options are ``VerifyConfig`` (``configs/verify.py``).
"""

from __future__ import annotations

from lerobot_mtdagger.commands.configs.verify import VerifyConfig
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.runner.configs import RunConfig

__all__ = ["VerifyConfig", "verify_command"]


def verify_command(config: VerifyConfig) -> list[str]:
    """Checks every committed round and policy against its files and record; exits 1 on a problem."""
    assert config.experiment_dir is not None  # VerifyConfig refuses None
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
