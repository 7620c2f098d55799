"""Every LeRobot name that moved between 0.4.4 and 0.6.1, and every private attribute we read: one place.

The package runs on LeRobot 0.4.x (Python < 3.12) and 0.6.x (Python >= 3.12); the test suite runs on
both (``.ci/run``), and ``scripts/check_lerobot_names.py`` checks the names against a LeRobot source tree.
Moved in 0.5/0.6:

- ``dataset_to_policy_features``: ``lerobot.datasets.utils`` -> ``lerobot.utils.feature_utils``;
- ``validate_frame``: ``lerobot.datasets.utils`` -> ``lerobot.datasets.feature_utils``;
- ``DEFAULT_FEATURES``: ``lerobot.datasets.utils`` -> ``lerobot.utils.constants``;
- ``get_hf_features_from_features``: ``lerobot.datasets.utils`` -> ``lerobot.datasets.feature_utils``,
  and a dataset no longer keeps ``hf_features`` (``dataset_hf_features`` builds them from its features);
- a dataset's unsaved frames: ``dataset.episode_buffer`` -> ``dataset.writer.episode_buffer`` (0.5.1);
- the step of ``save_episode`` that turns an episode's columns into a ``datasets.Dataset``:
  ``dataset._save_episode_data`` -> ``dataset.writer._save_episode_data`` (0.5.1; the dataset's
  method of that name only forwards there, and the writer's ``save_episode`` calls its own).

Everything else the package imports from LeRobot has one spelling in both lines (the script checks
that too). Behaviour that differs without a name moving is handled where it is used: LeRobot 0.6 logs
through named loggers (``utils/quiet.py``), reads ``meta/info.json`` into a typed ``DatasetInfo`` that
warns of and drops unknown keys on every load (so the round record lives in ``meta/mtdagger.json``, and
its mirror in ``info.json`` is written on 0.4 only: ``INFO_KEEPS_OTHER_KEYS``), and probes torchcodec
unless a dataset is created with a ``video_backend`` (``datasets/experiment_dir.py``).
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
    writer = getattr(dataset, "writer", None)
    buffer = writer.episode_buffer if hasattr(writer, "episode_buffer") else dataset.episode_buffer
    return int((buffer or {}).get("size", 0))


def episode_data_writer(dataset: Any) -> Any:
    """The object whose ``_save_episode_data`` LeRobot's ``save_episode`` calls for ``dataset``.

    LeRobot 0.4 writes an episode's columns in the dataset's own method (its ``writer`` attribute is
    then a ``pyarrow`` ``ParquetWriter`` or ``None``); from 0.5.1 the dataset holds an episode writer
    (``writer``, kept as ``_writer``) whose ``save_episode`` calls the writer's method of that name.
    """
    for name in ("writer", "_writer"):
        writer = getattr(dataset, name, None)
        if writer is not None and hasattr(writer, "_save_episode_data"):
            return writer
    return dataset
