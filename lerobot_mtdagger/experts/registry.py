"""The expert registry: which expert labels a task, keyed by suite family and task name.

A factory is registered for a suite family (``TaskSuite.expert_family``) and one task or all of
them, as a callable or a ``"module:attribute"`` entry point imported on first use::

    register_expert("metaworld", lambda suite, task: MyPPOExpert(task), task="push-v3")

``make_expert`` returns, in order of precedence, the suite's own (``suite.with_experts``), the
factory for ``(family, task)``, or the family's; wrapped in ``ActionCheckedExpert``.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from lerobot_mtdagger.experts.base import ActionCheckedExpert, Expert
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.registry import Registry

ANY_TASK = "*"
"""Task key of a factory that serves every task of its suite family."""

ExpertFactory = Callable[[Any, str], Expert]
"""``factory(suite, task_name) -> Expert``."""


def _refusal(key: tuple[str, str], factory: object) -> str:
    """The message refusing ``factory`` under ``key``, a ``(suite family, task)`` pair."""
    family, task = key
    return (
        f"The expert factory for {family}/{task} must be callable or a "
        f"'module:attribute' string, got {factory!r}."
    )


EXPERTS: Registry[tuple[str, str], ExpertFactory] = Registry("expert factory", refusal=_refusal)
"""Expert factories by ``(suite family, task)`` (``ANY_TASK``: every task of the family)."""


def register_expert(suite_family: str, factory: ExpertFactory | str, task: str = ANY_TASK) -> None:
    """Registers (or replaces) a family's task's expert factory (``TypeError``: not callable or a string)."""
    EXPERTS.register((suite_family, task), factory, replace=True)


for _family in ("metaworld", "drawers", "toy"):
    register_expert(_family, f"lerobot_mtdagger.experts.{_family}:scripted_expert")


def make_expert(suite: Any, task_name: str) -> ActionCheckedExpert:
    """The action-checked expert of a task of ``suite`` (``ValueError``: not built, or no expert)."""
    suite.check_buildable(task_name)
    expert = suite.expert_overrides.get(task_name)
    if expert is None:
        family = suite.expert_family
        key = next((key for key in ((family, task_name), (family, ANY_TASK)) if key in EXPERTS), None)
        if key is None:
            raise UserError(
                f"No expert is registered for task {task_name!r} of suite family {family!r}; register one "
                "with lerobot_mtdagger.experts.register_expert(family, factory) or give the suite one with "
                "suite.with_experts({task: expert})."
            )
        expert = EXPERTS.get(key)(suite, task_name)
    return ActionCheckedExpert(expert, task_name, suite.action_dim)
