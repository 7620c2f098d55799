"""Options of ``lerobot-mtdagger run``: ``RunConfig``, defined in ``runner/configs.py``.

Defined there because the runner reads it.
"""

from __future__ import annotations

from lerobot_mtdagger.runner.configs import RunConfig

__all__ = ["RunConfig"]
