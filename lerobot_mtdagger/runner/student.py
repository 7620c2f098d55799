"""The student contract (``Student``) and the registry of students by ``--policy.type``.

As LeRobot finds a policy class by name, the runner finds its student with ``get_student`` and asks
it for everything that differs between students::

    register_student("my-student", MyStudent)  # MyStudent(Student) or "my_package.students:MyStudent"

Built-in and installed students are entry points imported on first use: this module imports no torch.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
from collections.abc import Sequence
from typing import TYPE_CHECKING, Any, Generic, Protocol, TypeVar

from lerobot_mtdagger.datasets.student_types import (
    BUILTIN_STUDENT_TYPES,
    MTDAGGER_TYPE,
    add_student_policy_type,
)
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.plugins import STUDENT_ENTRY_POINTS
from lerobot_mtdagger.utils.registry import Registry

if TYPE_CHECKING:  # the contract's types, without importing torch or LeRobot here
    import torch
    from _typeshed import DataclassInstance
    from lerobot.policies.pretrained import PreTrainedPolicy
    from lerobot.processor import PolicyProcessorPipeline
    from torch.optim.lr_scheduler import LRScheduler

    from lerobot_mtdagger.runner.configs import RunConfig
    from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
    from lerobot_mtdagger.runner.training.normalise import NormalisedData
    from lerobot_mtdagger.runner.training.steps import StepOptions

OptionsT = TypeVar("OptionsT", bound="DataclassInstance")
"""A student's ``--policy.*`` options dataclass."""
PolicyConfigT = TypeVar("PolicyConfigT")
"""A student's policy config for a suite (what ``make_policy`` builds from)."""
Stats = dict[str, dict[str, Any]]
"""Normalisation statistics per feature (``mean``, ``std``, ``min``, ``max``: arrays)."""


class TrainingOps(Protocol):
    """One phase's training operations on a student's policy (what ``Student.phase_ops`` returns)."""

    @property
    def policy(self) -> PreTrainedPolicy:
        """The policy being trained."""

    def step_loss(self, index: torch.Tensor, first_of_interval: bool) -> torch.Tensor:
        """The training loss on the frames at ``index`` (the first of a log interval may log more)."""

    def task_losses(self, index: torch.Tensor, num_tasks: int) -> tuple[list[float | None], list[int]]:
        """The loss per task over frames ``index`` (None where a task has none) and the frame counts."""

    def optimizer(self, steps: int) -> tuple[torch.optim.Optimizer, LRScheduler | None, float]:
        """The optimiser, its learning-rate schedule over ``steps`` (or None) and the gradient clip norm."""


class Student(abc.ABC, Generic[OptionsT, PolicyConfigT]):
    """What the runner needs from a student policy (one per ``--policy.type``).

    Attributes:
        name: The ``--policy.type`` it is registered under.
        lr_option: The name of its learning-rate option (``--policy.<lr_option>``).
        policy_type: The LeRobot ``type`` of the policies it builds, which evaluation finds it by
            (None: ``name``).
    """

    lr_option: str = "lr"
    policy_type: str | None = None

    def __init__(self, name: str) -> None:
        """Names the student (its ``--policy.type``)."""
        self.name = name

    @property
    def saved_type(self) -> str:
        """The LeRobot ``type`` its saved policies carry."""
        return self.policy_type or self.name

    @abc.abstractmethod
    def options_class(self) -> type:
        """The dataclass of its ``--policy.*`` options (with ``batch_size`` and ``device``)."""

    def options_dict(self, options: OptionsT) -> dict[str, Any]:
        """JSON-ready options for the run's record, with ``type`` (the default student's omits it)."""
        values = dataclasses.asdict(options)
        return values if self.name == MTDAGGER_TYPE else {"type": self.name, **values}

    def task_dropout(self, options: OptionsT, unseen: bool) -> float:
        """The share of training frames whose task is hidden (``unseen``: the suite has held-out tasks).

        A student with none (the default) learns no task-free embedding, so its run evaluates no unseen task.
        """
        del options, unseen
        return 0.0

    def check_run(self, config: RunConfig) -> None:
        """Refuses run options the student cannot train with (none by default) with a ``ValueError``."""
        del config

    @abc.abstractmethod
    def policy_config(
        self, options: OptionsT, suite_features: dict[str, Any], task_names: Sequence[str], unseen: bool
    ) -> PolicyConfigT:
        """Its policy config for a suite: ``task_names``, ``image_features``, ``task_dropout`` and ``device``.

        ``unseen``: the suite has held-out tasks (task dropout may then apply).
        """

    @abc.abstractmethod
    def make_policy(
        self, policy_cfg: PolicyConfigT, stats: Stats
    ) -> tuple[PreTrainedPolicy, PolicyProcessorPipeline, PolicyProcessorPipeline]:
        """A freshly initialised policy on its config's device, its pre- and its post-processor for ``stats``.

        Draw the weights on the CPU (then move them), so a seed gives the same weights on every device.
        """

    @abc.abstractmethod
    def phase_ops(self, policy: PreTrainedPolicy, data: NormalisedData, options: StepOptions) -> TrainingOps:
        """Its training operations for one phase on the phase's frames ``data``."""

    @abc.abstractmethod
    def previous_losses(
        self, runner: PolicyRunner, data: NormalisedData, index: torch.Tensor, options: StepOptions
    ) -> list[float | None]:
        """The previous phase's policy's (``runner``) per-task loss on this phase's frames ``index``."""

    @abc.abstractmethod
    def make_runner(
        self,
        policy: PreTrainedPolicy,
        preprocessor: PolicyProcessorPipeline,
        postprocessor: PolicyProcessorPipeline,
    ) -> PolicyRunner:
        """Its evaluation runner (``evaluate.PolicyRunner`` or a subclass): batched actions."""


StudentEntry = type[Student[Any, Any]] | str
"""A ``Student`` subclass, or its ``"module:attribute"`` entry point."""


def _refusal(name: str, student: object) -> str:
    """The ``TypeError`` message for a registration neither a ``Student`` subclass nor an entry point."""
    if isinstance(student, str):
        return f"The student {name!r} must be a 'module:attribute' string, got {student!r}."
    return f"The student {name!r} must be a Student subclass, got {student!r}."


STUDENTS: Registry[str, type[Student[Any, Any]]] = Registry(
    "student",
    accepts=lambda student: isinstance(student, type) and issubclass(student, Student),
    entry_point_group=STUDENT_ENTRY_POINTS,
    refusal=_refusal,
)
"""The students by ``--policy.type``."""


def register_student(name: str, student: StudentEntry) -> None:
    """Registers the student of a ``--policy.type``: a ``Student`` subclass or its ``"module:attribute"``.

    Raises:
        UserError: If ``name`` is already registered.
        TypeError: If ``student`` is neither a ``Student`` subclass nor an entry-point string.
    """
    STUDENTS.register(name, student)
    # an entry point's saved type is added when the student is built
    add_student_policy_type(name if isinstance(student, str) else student.policy_type or name)


def student_names() -> list[str]:
    """Every registered ``--policy.type``, the built-in ones first."""
    return STUDENTS.names()


def check_student_name(name: str) -> str:
    """``name`` if a student is registered under it, without building it (else a one-line ``UserError``)."""
    if name not in STUDENTS:
        raise UserError(
            f"Unknown --policy.type {name!r}; registered students: {', '.join(student_names())} (a student "
            "from outside the package is registered with lerobot_mtdagger.runner.student.register_student, "
            f"or installed by a package's entry point in the group {STUDENT_ENTRY_POINTS!r})."
        )
    return name


def get_student(name: str) -> Student[Any, Any]:
    """The student of a ``--policy.type`` (``UserError`` on an unregistered name or a failing entry point)."""
    check_student_name(name)
    return _student(name, STUDENTS.entry(name), STUDENTS.get(name))


@functools.cache
def _student(name: str, entry: StudentEntry, student_class: type[Student[Any, Any]]) -> Student[Any, Any]:
    """The student built from a registry entry (once per name and entry)."""
    del entry  # the cache key: a name registered anew builds anew
    student = student_class(name)
    add_student_policy_type(student.saved_type)
    return student


def student_of_options(options: object) -> Student[Any, Any]:
    """The student whose options class ``options`` is exactly (``ValueError`` if none)."""
    for name in student_names():
        student = get_student(name)
        if type(options) is student.options_class():
            return student
    raise ValueError(f"{type(options)} is not a student policy's options class.")


def student_of_policy(policy: PreTrainedPolicy) -> Student[Any, Any]:
    """The student that built ``policy`` (by its config's ``type``); a ``UserError`` if none."""
    policy_type = policy.config.type
    if policy_type in STUDENTS:
        return get_student(policy_type)
    for name in student_names():
        if get_student(name).saved_type == policy_type:
            return get_student(name)
    return get_student(policy_type)  # refused, listing the registered students


_BUILTIN_ENTRIES = {
    MTDAGGER_TYPE: "lerobot_mtdagger.students.mtdagger:MTDAggerStudent",
    "diffusion": "lerobot_mtdagger.students.lerobot:DiffusionStudent",
}
for _name in BUILTIN_STUDENT_TYPES:
    register_student(_name, _BUILTIN_ENTRIES.get(_name, "lerobot_mtdagger.students.lerobot:LeRobotStudent"))
STUDENTS.load_entry_points(register_student)
