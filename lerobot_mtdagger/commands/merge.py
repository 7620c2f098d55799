"""``lerobot-mtdagger merge``: rounds 0..k of an experiment as ONE LeRobotDataset.

Its options are ``MergeConfig`` (``configs/merge.py``).
"""

from __future__ import annotations

from pathlib import Path

from lerobot_mtdagger.commands.configs.merge import MergeConfig
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, merge_rounds
from lerobot_mtdagger.datasets.verify import check_before_reading
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.utils.errors import UserError

__all__ = ["MergeConfig", "merge_command"]


def merge_command(config: MergeConfig) -> Path:
    """Merges rounds 0..k with LeRobot's aggregation; the result trains with stock lerobot-train."""
    assert config.experiment_dir is not None and config.output is not None  # MergeConfig refuses None
    experiment = ExperimentDir(config.experiment_dir)
    experiment.read_config()  # refuses a folder that is not an experiment
    unverified = check_before_reading(experiment, config.unverified, RunConfig.option_defaults())
    rounds = experiment.committed_rounds()
    if not rounds:
        raise UserError(f"{config.experiment_dir} has no committed round to merge yet.")
    last = rounds[-1] if config.up_to_round is None else config.up_to_round
    if last not in rounds:
        raise UserError(f"Round {last} is not committed in {config.experiment_dir}; committed: {rounds}.")
    output = merge_rounds(experiment, list(range(last + 1)), config.output, config.repo_id, unverified)
    print(f"merged rounds 0..{last} into {output}")
    return output
