"""The student contract (``Student``) and the registry of students by ``--policy.type``.

As LeRobot names its policies (``PreTrainedPolicy`` subclasses, found by ``get_policy_class(name)``),
the runner finds the student of a run by its ``--policy.type`` (``get_student(name)``) and asks it,
through ``Student``, for everything that differs between students: its options, its policy config
and policy, its training seam, the previous phase's loss and its evaluation runner. The built-in
students (``datasets.student_types.BUILTIN_STUDENT_TYPES``) are registered below as entry points,
imported on first use, so parsing the options of ``mtdagger`` never imports LeRobot's policies::

    register_student("my-student", MyStudent)  # MyStudent(Student) or "my_package.students:MyStudent"

An installed package registers its students by entry point (group ``lerobot_mtdagger.students``,
``utils.plugins``), so ``lerobot-mtdagger run --policy.type=<its name>`` finds them.

Reading this module imports no torch and no LeRobot.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
from collections.abc import Hashable, Sequence
from typing import Any

from lerobot_mtdagger.datasets.student_types import (
    BUILTIN_STUDENT_TYPES,
    MTDAGGER_TYPE,
    add_student_policy_type,
)
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.plugins import STUDENT_ENTRY_POINTS
from lerobot_mtdagger.utils.registry import Registry


class Student(abc.ABC):
    """What the runner needs from a student policy (one per ``--policy.type``).

    A student is built with its registered name; ``policy_type`` is the LeRobot policy type of the
    policies it saves (None: its name), which evaluation finds it by.

    Attributes:
        name: The ``--policy.type`` it is registered under.
        lr_option: The name of its learning-rate option (``--policy.<lr_option>``).
        policy_type: The LeRobot ``type`` of the policies it builds (None: ``name``).
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

    def options_dict(self, options: Any) -> dict[str, Any]:
        """JSON-ready options for the run's record, with ``type`` (the default student's omits it).

        Args:
            options: Its options (an instance of ``options_class()``).
        """
        values = dataclasses.asdict(options)
        return values if self.name == MTDAGGER_TYPE else {"type": self.name, **values}

    def check_run(self, config: Any) -> None:
        """Refuses run options the student cannot train with (none by default).

        Args:
            config: The run's ``RunConfig``.

        Raises:
            ValueError: Naming the option and the fix.
        """
        del config

    @abc.abstractmethod
    def policy_config(
        self, options: Any, suite_features: dict[str, Any], task_names: Sequence[str], unseen: bool
    ) -> Any:
        """Its policy config for a suite.

        Args:
            options: Its ``--policy.*`` options.
            suite_features: The suite's dataset features.
            task_names: The training tasks, in order.
            unseen: Whether the suite has held-out tasks (task dropout may then apply).

        Returns:
            A config with ``task_names``, ``image_features``, ``task_dropout`` and ``device``.
        """

    @abc.abstractmethod
    def make_policy(self, policy_cfg: Any, stats: dict[str, dict[str, Any]]) -> tuple[Any, Any, Any]:
        """A freshly initialised policy on its config's device and its processors for ``stats``.

        Draw the weights on the CPU (then move them), so that a seed gives the same weights on
        every device.

        Returns:
            The policy, its pre-processor and its post-processor.
        """

    @abc.abstractmethod
    def phase_ops(self, policy: Any, data: Any, options: Any) -> Any:
        """Its training seam for one phase (``step_loss``, ``task_losses``, ``optimizer``).

        Args:
            policy: The policy to train.
            data: The phase's normalised frames (``normalise.NormalisedData``).
            options: The phase's ``steps.StepOptions``.
        """

    @abc.abstractmethod
    def previous_losses(self, runner: Any, data: Any, index: Any, options: Any) -> list[float | None]:
        """The previous phase's policy's per-task loss on this phase's frames (performance gain's start).

        Args:
            runner: The previous phase's policy (``evaluate.PolicyRunner``).
            data: This phase's normalised frames.
            index: The frames to measure on.
            options: This phase's ``steps.StepOptions``.
        """

    @abc.abstractmethod
    def make_runner(self, policy: Any, preprocessor: Any, postprocessor: Any) -> Any:
        """Its evaluation runner (``evaluate.PolicyRunner`` or a subclass): batched actions."""


StudentEntry = type[Student] | str
"""A ``Student`` subclass, or its ``"module:attribute"`` entry point."""


def _refusal(name: Hashable, student: object) -> str:
    """The ``TypeError`` message for a registration neither a ``Student`` subclass nor an entry point."""
    if isinstance(student, str):
        return f"The student {name!r} must be a 'module:attribute' string, got {student!r}."
    return f"The student {name!r} must be a Student subclass, got {student!r}."


STUDENTS: Registry[type[Student]] = Registry(
    "student",
    accepts=lambda student: isinstance(student, type) and issubclass(student, Student),
    entry_point_group=STUDENT_ENTRY_POINTS,
    refusal=_refusal,
)
"""The students by ``--policy.type``."""


def register_student(name: str, student: StudentEntry) -> None:
    """Registers the student of a ``--policy.type``.

    Args:
        name: The ``--policy.type``.
        student: A ``Student`` subclass (built with ``name``), or its ``"module:attribute"`` entry
            point, imported when the student is first asked for.

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
    """``name`` if a student is registered under it, without building the student.

    Raises:
        UserError: On a name no student is registered for (one line listing the registered ones).
    """
    if name not in STUDENTS:
        raise UserError(
            f"Unknown --policy.type {name!r}; registered students: {', '.join(student_names())} (a student "
            "from outside the package is registered with lerobot_mtdagger.runner.student.register_student, "
            f"or installed by a package's entry point in the group {STUDENT_ENTRY_POINTS!r})."
        )
    return name


def get_student(name: str) -> Student:
    """The student of a ``--policy.type``.

    Raises:
        UserError: On a name no student is registered for (one line listing the registered ones), or
            an entry point that does not import.
    """
    check_student_name(name)
    return _student(name, STUDENTS.entry(name), STUDENTS.get(name))


@functools.cache
def _student(name: str, entry: StudentEntry, student_class: type[Student]) -> Student:
    """The student built from a registry entry (once per name and entry)."""
    del entry  # the cache key: a name registered anew builds anew
    student = student_class(name)
    add_student_policy_type(student.saved_type)
    return student


def student_of_options(options: Any) -> Student:
    """The student whose options class ``options`` is (exactly).

    Raises:
        ValueError: If no registered student takes options of that class.
    """
    for name in student_names():
        student = get_student(name)
        if type(options) is student.options_class():
            return student
    raise ValueError(f"{type(options)} is not a student policy's options class.")


def student_of_policy(policy: Any) -> Student:
    """The student that built ``policy``: the one named by its config's ``type``, or whose policy type it is.

    Raises:
        UserError: If no registered student builds policies of that type.
    """
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
