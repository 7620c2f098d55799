"""Names of an experiment folder's files and folders, in a module that imports nothing.

Record readers and the command line's path checks know them without loading LeRobot or torch.
"""

from __future__ import annotations

from pathlib import Path

from lerobot_mtdagger.utils.errors import NotAnExperimentError

ROUNDS_DIR = "rounds"
POLICIES_DIR = "policies"
STAGING_DIR = ".staging"
PROGRESS_DIR = ".progress"
"""Under ``policies/``: the saved progress of phases being trained (``runner.training.phase_progress``)."""
PARTIAL_SUFFIX = ".partial"
"""Added to a progress file's name while it is written (then renamed onto it)."""
TRAINING_FILE = "training.json"
CONFIG_FILE = "config.json"
LOCK_FILE = ".lock"
"""The writer lock of an experiment folder (an OS lock held while a run writes; it holds the pid)."""
POLICY_PATH_TAKES = (
    "a policy folder (config.json, model.safetensors, processors; e.g. <experiment>/policies/round-003) or a "
    "Hub id owner/name"
)
"""What ``--policy_path`` takes (``eval``, ``shift``), for messages."""


def check_experiment_folder(root: Path) -> None:
    """Refuses a folder that holds no experiment: missing, not a folder, or without ``config.json``.

    Raises:
        NotAnExperimentError: Naming the folder and what to pass instead.
    """
    if not root.is_dir():
        raise NotAnExperimentError(
            f"{root} does not exist or is not a folder: pass the --output_dir of a `lerobot-mtdagger run`."
        )
    if not (root / CONFIG_FILE).is_file():
        raise NotAnExperimentError(
            f"{root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}): pass the --output_dir of a "
            "`lerobot-mtdagger run`; the folder was left untouched."
        )
