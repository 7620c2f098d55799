"""``lerobot-mtdagger merge``: rounds 0..k of an experiment as ONE LeRobotDataset."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.paths import check_output_dir


@dataclass
class MergeConfig:
    """Options of ``lerobot-mtdagger merge``: D(k) = rounds 0..k as ONE LeRobotDataset.

    Attributes:
        experiment_dir: The experiment's output directory.
        output: Folder of the merged dataset (must not exist).
        up_to_round: Last round to merge (None: the last committed one).
        repo_id: Repo id written into the merged dataset's metadata.
        unverified: Merge an experiment that fails verification (a changed record or file, a missing
            ledger) as it is, with a warning; the merged record lists the problems under ``unverified``.
            By default such an experiment is refused before anything is written.
    """

    experiment_dir: Path | None = None
    output: Path | None = None
    up_to_round: int | None = None
    repo_id: str = "local/merged"
    unverified: bool = False

    def __post_init__(self) -> None:
        if self.experiment_dir is None or self.output is None:
            raise ValueError("--experiment_dir and --output are required.")
        check_output_dir(self.output, "--output")


def merge_command(config: MergeConfig) -> Path:
    """Merges rounds 0..k with LeRobot's aggregation; the result trains with stock lerobot-train."""
    from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, merge_rounds
    from lerobot_mtdagger.datasets.verify import check_before_reading
    from lerobot_mtdagger.runner.configs import RunConfig

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
