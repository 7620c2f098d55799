"""Every LeRobot name that moved between 0.4.4 and 0.6.1, and every private attribute we read: one place.

The package runs on LeRobot 0.4.x (Python < 3.12) and 0.6.x (Python >= 3.12);
``scripts/check_lerobot_names.py`` checks the names below against a LeRobot source tree. Behaviour
that differs without a name moving is handled where it is used: LeRobot 0.6 logs through named
loggers (``utils/quiet.py``), drops unknown keys of ``meta/info.json`` (so the round record lives in
``meta/mtdagger.json``; ``INFO_KEEPS_OTHER_KEYS``), and probes torchcodec unless a dataset is created
with a ``video_backend`` (``datasets/experiment_dir.py``).
"""

from __future__ import annotations

from typing import Any

try:  # LeRobot >= 0.5
    from lerobot.utils.feature_utils import dataset_to_policy_features
except ImportError:  # LeRobot 0.4
    from lerobot.datasets.utils import dataset_to_policy_features

try:  # LeRobot >= 0.5
    from lerobot.datasets.feature_utils import validate_frame
except ImportError:  # LeRobot 0.4
    from lerobot.datasets.utils import validate_frame

try:  # LeRobot >= 0.5
    from lerobot.utils.constants import DEFAULT_FEATURES
except ImportError:  # LeRobot 0.4
    from lerobot.datasets.utils import DEFAULT_FEATURES

try:  # LeRobot >= 0.5
    from lerobot.datasets.feature_utils import get_hf_features_from_features
except ImportError:  # LeRobot 0.4
    from lerobot.datasets.utils import get_hf_features_from_features

try:  # LeRobot >= 0.6: info.json read into a typed DatasetInfo, other keys warned of and dropped
    from lerobot.datasets.utils import DatasetInfo  # noqa: F401

    INFO_KEEPS_OTHER_KEYS = False
except ImportError:  # LeRobot 0.4: info.json read as a dict, other keys kept
    INFO_KEEPS_OTHER_KEYS = True

__all__ = [
    "DEFAULT_FEATURES",
    "INFO_KEEPS_OTHER_KEYS",
    "dataset_hf_features",
    "dataset_to_policy_features",
    "episode_data_writer",
    "unsaved_frames",
    "validate_frame",
]


def dataset_hf_features(dataset: Any) -> Any:
    """The ``datasets.Features`` of a ``LeRobotDataset``'s frames (0.4 kept them as ``hf_features``)."""
    return get_hf_features_from_features(dataset.meta.features)


def unsaved_frames(dataset: Any) -> int:
    """Frames added to a ``LeRobotDataset`` and not saved in an episode yet (its episode buffer's size)."""
    # LeRobot >= 0.5.1 keeps the buffer in its writer; 0.4 in the dataset (whose ``writer`` is then a
    # ParquetWriter once a data file is open, or None)
    writer: Any = getattr(dataset, "writer", None)
    buffer = writer.episode_buffer if hasattr(writer, "episode_buffer") else dataset.episode_buffer
    return int((buffer or {}).get("size", 0))


def episode_data_writer(dataset: Any) -> Any:
    """The object whose ``_save_episode_data`` LeRobot's ``save_episode`` calls (0.4: the dataset itself)."""
    for name in ("writer", "_writer"):
        writer = getattr(dataset, name, None)
        if writer is not None and hasattr(writer, "_save_episode_data"):
            return writer
    return dataset
