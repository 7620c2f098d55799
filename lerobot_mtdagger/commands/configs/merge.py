"""Options of ``lerobot-mtdagger merge``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lerobot_mtdagger.datasets.experiment_files import check_experiment_folder
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

    def check_paths(self) -> None:
        """Refuses an ``--experiment_dir`` that holds no experiment, and an ``--output`` that exists.

        Raises:
            UserError: Naming the folder and the fix.
        """
        assert self.experiment_dir is not None and self.output is not None  # __post_init__ refused None
        check_experiment_folder(Path(self.experiment_dir))
        if Path(self.output).exists():
            raise UserError(f"Merge target {self.output} exists; choose another --output or delete it.")
