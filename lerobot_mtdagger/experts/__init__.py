"""Experts: the ``Expert`` protocol, adapters for other policies, and the registry of each suite's.

``make_expert(suite, task_name)`` gives the expert of a task (see ``registry``). The scripted experts
of the built-in suites are registered by entry point and imported on first use: MetaWorld's policies
(``metaworld``), the drawer controller (``drawers``) and the toy suite's optimal controller (``toy``).
``ExpertNoise`` (``noise``) makes any expert imperfect, the way a stochastic RL policy acts;
``--expert.path`` and ``--expert.type`` (``command_line``) name experts from the command line.
Experts depend on the suites (they read the privileged state layout); suites never import experts.
"""

from lerobot_mtdagger.experts.base import (
    ActionCheckedExpert,
    CallableExpert,
    Expert,
    ExpertEpisode,
    LeRobotPolicyExpert,
    run_expert_episode,
)
from lerobot_mtdagger.experts.command_line import register_expert_type
from lerobot_mtdagger.experts.noise import ActionNoise, ExpertNoise
from lerobot_mtdagger.experts.registry import ANY_TASK, make_expert, register_expert

__all__ = [
    "ANY_TASK",
    "ActionCheckedExpert",
    "ActionNoise",
    "CallableExpert",
    "Expert",
    "ExpertEpisode",
    "ExpertNoise",
    "LeRobotPolicyExpert",
    "make_expert",
    "register_expert",
    "register_expert_type",
    "run_expert_episode",
]
