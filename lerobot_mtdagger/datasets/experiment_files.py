"""Names of an experiment folder's files and folders, in a module that imports nothing (no LeRobot)."""

from __future__ import annotations

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
