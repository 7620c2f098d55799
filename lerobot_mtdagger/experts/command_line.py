"""Experts named on the command line: ``--expert.path`` (LeRobot policy folders) and ``--expert.type``.

``--expert.path=experts/`` holds a policy folder per task; a folder with ``config.json`` is one
multitask policy (handed each episode's task string). Each policy's ``observation.state`` input is
the suite's privileged state. ``--expert.type`` names a factory ``factory(suite, task) -> Expert``
(:func:`register_expert_type`, or ``module:attribute``). Both are checked before anything is written.
"""

from __future__ import annotations

import copy
import inspect
from collections.abc import Callable
from pathlib import Path
from typing import Any

from lerobot_mtdagger.datasets.checkpoints import check_local_policy, load_policy
from lerobot_mtdagger.experts.base import Expert, LeRobotPolicyExpert
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.plugins import EXPERT_ENTRY_POINTS
from lerobot_mtdagger.utils.registry import EntryPointError, Registry, resolve

STATE_KEY = "observation.state"
"""The input a policy expert reads the privileged state from."""

EXPERT_TYPES: Registry[str, Callable[[Any, str], Expert]] = Registry(
    "expert type", entry_point_group=EXPERT_ENTRY_POINTS
)
"""Expert factories by the name ``--expert.type`` gives (installed ones by entry point)."""


def register_expert_type(name: str, factory: Callable[[Any, str], Expert]) -> None:
    """Registers (or replaces) an expert factory as a ``--expert.type`` name (``TypeError``: not callable)."""
    if not callable(factory):
        raise TypeError(f"The expert type {name!r} needs a callable factory(suite, task), got {factory!r}.")
    EXPERT_TYPES.register(name, factory, replace=True)


def expert_type_factory(name: str) -> Callable[[Any, str], Expert]:
    """The ``--expert.type`` factory: a registered name or ``module:attribute`` (else a ``UserError``)."""
    if name in EXPERT_TYPES:
        return EXPERT_TYPES.get(name)
    known = sorted(EXPERT_TYPES.names()) or "none"
    hint = (
        f"--expert.type={name} is neither a registered expert type ({known}) nor an importable "
        "module:attribute factory(suite, task) -> Expert"
    )
    try:
        factory = resolve(name)
    except EntryPointError as error:
        cause = f" ({type(error.cause).__name__}: {error.cause})" if error.cause else ""
        raise UserError(f"{hint}{cause}.") from None
    if not callable(factory):
        raise UserError(f"{hint} ({name} is a {type(factory).__name__}, not callable).")
    return factory


EXPERT_TYPES.load_entry_points()


def privileged_state_size(suite: Any) -> int:
    """The size of the suite's privileged state (from one reset of its first task's env)."""
    env = suite.make_env(suite.task_names[0])
    try:
        _, info = env.reset(seed=0)
        return int(info["privileged_state"].shape[-1])
    finally:
        env.close()


def _policy_input_size(policy: Any, folder: Path) -> int:
    """The size of a policy's ``observation.state`` input (``UserError`` if it has none)."""
    feature = policy.config.input_features.get(STATE_KEY)
    if feature is None:
        inputs = sorted(policy.config.input_features)
        raise UserError(
            f"The expert policy {folder} reads {inputs}, not {STATE_KEY!r}: an expert acts on the privileged "
            f"state, fed as {STATE_KEY!r}; train it on that."
        )
    return int(feature.shape[-1])


def _load_expert_policy(folder: Path, state_size: int) -> tuple[Any, Any, Any]:
    """Loads and checks one expert policy folder (its input is the privileged state)."""
    check_local_policy(folder)
    policy, pre, post = load_policy(folder)
    size = _policy_input_size(policy, folder)
    if size != state_size:
        raise UserError(
            f"The expert policy {folder} reads a {STATE_KEY} of size {size}, but this suite's privileged "
            f"state has size {state_size}: give a policy trained on this suite's privileged state."
        )
    return policy, pre, post


def policy_experts(path: Path, suite: Any) -> dict[str, LeRobotPolicyExpert]:
    """The experts of every task of ``suite`` from ``--expert.path`` (see the module docstring).

    Raises:
        UserError: If the path is missing, a folder is not a policy, a policy's input is not the
            privileged state, or a task has no expert.
    """
    path = Path(path)
    if not path.is_dir():
        raise UserError(
            f"--expert.path={path} is not a folder: give a policy folder (one multitask expert) or a "
            "folder with one policy folder per task, named after the task."
        )
    state_size = privileged_state_size(suite)
    if (path / "config.json").is_file():
        policy, pre, post = _load_expert_policy(path, state_size)
        known = getattr(policy.config, "task_names", None)
        unknown = [task for task in suite.task_names if known and task not in known]
        if unknown:
            raise UserError(
                f"The multitask expert policy {path} was not trained on the tasks {unknown}: give one "
                "trained on every task of the suite, or one policy folder per task."
            )
        # a copy per task: a policy with an action queue (ACT, Diffusion) keeps one per running episode
        tasks = suite.task_names
        return {task: LeRobotPolicyExpert(copy.deepcopy(policy), pre, post, task=task) for task in tasks}
    missing = [task for task in suite.task_names if not (path / task).is_dir()]
    if missing:
        raise UserError(
            f"--expert.path={path} has no expert for the tasks {missing}: add a policy folder {path}/<task> "
            "for each (or give one multitask policy folder)."
        )
    experts = {}
    for task in suite.task_names:
        policy, pre, post = _load_expert_policy(path / task, state_size)
        experts[task] = LeRobotPolicyExpert(policy, pre, post, task=task)  # a policy may read the task
    return experts


def command_line_experts(suite: Any, path: str | None, type_name: str | None) -> Any:
    """``suite`` with the experts the command line names (``UserError`` on a bad path or type)."""
    if path is not None:
        return suite.with_experts(policy_experts(Path(path), suite))
    if type_name is not None:
        factory = expert_type_factory(type_name)
        experts = {task: _expert_of(factory, type_name, suite, task) for task in suite.task_names}
        return suite.with_experts(experts)
    return suite


def _expert_of(factory: Callable[..., Any], type_name: str, suite: Any, task: str) -> Expert:
    """The checked expert ``factory(suite, task)`` gives (``UserError`` if the call fails or gives none)."""
    fix = "give --expert.type a factory(suite, task) that returns an object with reset() and act(state)"
    try:
        inspect.signature(factory).bind(suite, task)
    except TypeError as error:
        message = f"--expert.type={type_name} is not a factory(suite, task) ({error}); {fix}."
        raise UserError(message) from None
    except ValueError:
        pass  # a callable without a readable signature (some built-ins): the call itself tells
    expert = factory(suite, task)
    if not isinstance(expert, Expert):
        raise UserError(
            f"--expert.type={type_name} gave a {type(expert).__name__} for the task {task!r}, not an expert; "
            f"{fix}."
        )
    return expert
