"""Experts: the ``Expert`` protocol, adapters for other policies, and the registry of each suite's.

``make_expert(suite, task_name)`` gives the expert of a task; the built-in suites' scripted experts
(``metaworld``, ``drawers``, ``toy``) are registered by entry point and imported on first use.
Experts read the suites' privileged state layout; suites never import experts.
"""

from __future__ import annotations

import importlib
from typing import Any

_HOME = {
    "ActionCheckedExpert": "base",
    "CallableExpert": "base",
    "Expert": "base",
    "ExpertEpisode": "base",
    "LeRobotPolicyExpert": "base",
    "run_expert_episode": "base",
    "register_expert_type": "command_line",
    "ActionNoise": "noise",
    "ExpertNoise": "noise",
    "ANY_TASK": "registry",
    "make_expert": "registry",
    "register_expert": "registry",
}
"""Where each public name lives: imported on first use, so that ``experts.noise`` (which the command-line
configs need) does not pull torch and LeRobot in with the adapters."""


def __getattr__(name: str) -> Any:
    """The public name ``name``, from its module (PEP 562)."""
    if name not in _HOME:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    return getattr(importlib.import_module(f"{__name__}.{_HOME[name]}"), name)


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
