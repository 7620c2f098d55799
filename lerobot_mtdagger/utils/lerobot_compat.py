"""Every LeRobot name that moved between 0.4.4 and 0.6.1, and every private attribute we read: one place.

The package runs on LeRobot 0.4.x (Python 3.11, tested here) and is written for 0.6.x (Python >= 3.12,
checked by reading its sources with ``scripts/check_lerobot_names.py``, not run). Moved in 0.5/0.6:

- ``dataset_to_policy_features``: ``lerobot.datasets.utils`` -> ``lerobot.utils.feature_utils``;
- ``validate_frame``: ``lerobot.datasets.utils`` -> ``lerobot.datasets.feature_utils``;
- ``DEFAULT_FEATURES``: ``lerobot.datasets.utils`` -> ``lerobot.utils.constants``;
- ``get_hf_features_from_features``: ``lerobot.datasets.utils`` -> ``lerobot.datasets.feature_utils``,
  and a dataset no longer keeps ``hf_features`` (``dataset_hf_features`` builds them from its features);
- a dataset's unsaved frames: ``dataset.episode_buffer`` -> ``dataset.writer.episode_buffer`` (0.5.1).

Everything else the package imports from LeRobot has one spelling in both lines (the script checks
that too).
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

__all__ = [
    "DEFAULT_FEATURES",
    "dataset_hf_features",
    "dataset_to_policy_features",
    "unsaved_frames",
    "validate_frame",
]


def dataset_hf_features(dataset: Any) -> Any:
    """The ``datasets.Features`` of a ``LeRobotDataset``'s frames (0.4 kept them as ``hf_features``)."""
    return get_hf_features_from_features(dataset.meta.features)


def unsaved_frames(dataset: Any) -> int:
    """Frames added to a ``LeRobotDataset`` and not saved in an episode yet (its episode buffer's size)."""
    writer = getattr(dataset, "writer", None)  # LeRobot >= 0.5.1 keeps the buffer in its writer
    buffer = getattr(writer, "episode_buffer", None) if writer is not None else dataset.episode_buffer
    return int((buffer or {}).get("size", 0))
