"""Options of ``lerobot-mtdagger plan``: ``PlanConfig``, defined in ``planning/plan.py``.

Defined there because ``make_plan`` reads it.
"""

from __future__ import annotations

from lerobot_mtdagger.planning.plan import PlanConfig

__all__ = ["PlanConfig"]
