"""Options of ``lerobot-mtdagger verify``."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lerobot_mtdagger.datasets.experiment_files import check_experiment_folder


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

    def check_paths(self) -> None:
        """Refuses an ``--experiment_dir`` that holds no experiment.

        Raises:
            NotAnExperimentError: Naming the folder and what to pass instead.
        """
        assert self.experiment_dir is not None  # __post_init__ refused None
        check_experiment_folder(Path(self.experiment_dir))
