"""Options of ``lerobot-mtdagger shift``: ``eval``'s, with fewer episodes by default."""

from __future__ import annotations

from dataclasses import dataclass

from lerobot_mtdagger.commands.configs.eval import EvalConfig


@dataclass
class ShiftConfig(EvalConfig):
    """Options of ``lerobot-mtdagger shift``: a policy's action error on its own states vs the expert's.

    The attributes are ``EvalConfig``'s; ``episodes`` episodes per task are run by the policy and
    again by the expert from the same reset seeds (``shift.measure_shift``).
    """

    episodes: int = 5
