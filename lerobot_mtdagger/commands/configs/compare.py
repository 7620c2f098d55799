"""Options of ``lerobot-mtdagger compare``: ``CompareConfig``, defined in ``analysis/compare.py``.

Any option that is not compare's own goes to every run (``split_arguments``).
"""

from __future__ import annotations

from lerobot_mtdagger.analysis.compare import CompareConfig, split_arguments

__all__ = ["CompareConfig", "split_arguments"]
