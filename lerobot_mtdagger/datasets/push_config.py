"""Options of ``lerobot-mtdagger push`` (apart from ``hub.py``, so that parsing them imports no LeRobot)."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from lerobot_mtdagger.datasets.experiment_files import check_experiment_folder


@dataclass
class PushConfig:
    """Options of ``lerobot-mtdagger push``: an experiment to the Hub, round k as revision ``round-{k:03d}``.

    Attributes:
        experiment_dir: The experiment's output directory.
        repo_id: Hub dataset repo for the rounds, ``owner/name``.
        policy_repo_id: Hub model repo for the trained policies (None: policies are not pushed).
        private: Whether repos created by the push are private.
    """

    experiment_dir: Path | None = None
    repo_id: str | None = None
    policy_repo_id: str | None = None
    private: bool = False

    def __post_init__(self) -> None:
        if self.experiment_dir is None:
            raise ValueError(
                "--experiment_dir is required: pass the --output_dir of a `lerobot-mtdagger run`, "
                "e.g. --experiment_dir=outputs/mt10."
            )
        if self.repo_id is None:
            raise ValueError(
                "--repo_id is required: the Hub dataset repo to push the rounds to, "
                "e.g. --repo_id=<user>/mtdagger-mt10."
            )

    def check_paths(self) -> None:
        """Refuses an ``--experiment_dir`` that holds no experiment, before anything is sent.

        Raises:
            NotAnExperimentError: Naming the folder and what to pass instead.
        """
        assert self.experiment_dir is not None  # __post_init__ refused None
        check_experiment_folder(Path(self.experiment_dir))
