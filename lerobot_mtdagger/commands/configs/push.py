"""Options of ``lerobot-mtdagger push``: ``PushConfig``, defined in ``datasets/push_config.py``."""

from __future__ import annotations

from lerobot_mtdagger.datasets.push_config import PushConfig

__all__ = ["PushConfig"]
