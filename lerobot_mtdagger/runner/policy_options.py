"""The run's ``--policy.*`` options: the default student's (``PolicyOptions``) or another student's.

Other students' options classes are offered to the parser only when the options name one
(``students_for``), so parsing a ``mtdagger`` run's options imports no torch and no LeRobot.
"""

from __future__ import annotations

import contextlib
import contextvars
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any

from lerobot_mtdagger.datasets.student_types import MTDAGGER_TYPE
from lerobot_mtdagger.runner.student import check_student_name, get_student, student_names, student_of_options


@dataclass
class PolicyOptions:
    """Options of the ``mtdagger`` policy and its training (None: from the preset).

    Attributes:
        batch_size: Training batch size.
        lr: AdamW learning rate.
        state_hidden_dims: Hidden sizes of the state MLP.
        head_hidden_dims: Hidden sizes of the action head.
        pointnet_dims: PointNet per-point MLP sizes.
        pointnet_layer_norm: LayerNorm after every PointNet layer and its projection (DP3's encoder).
        pointcloud_embedding_dim: Output size of the point-cloud encoder.
        task_embedding_dim: Task embedding size.
        task_dropout: Probability of training a sample on the shared "any task" embedding, which lets
            the policy act on unseen tasks. None: ``UNSEEN_TASK_DROPOUT`` with held-out tasks, else 0.
        device: Torch device.
    """

    batch_size: int | None = None
    lr: float | None = None
    state_hidden_dims: list[int] = field(default_factory=lambda: [256, 256])
    head_hidden_dims: list[int] = field(default_factory=lambda: [256, 256])
    pointnet_dims: list[int] = field(default_factory=lambda: [64, 128, 256])
    pointnet_layer_norm: bool = False
    pointcloud_embedding_dim: int = 256
    task_embedding_dim: int = 32
    task_dropout: float | None = None
    device: str = "cpu"

    def resolved_task_dropout(self, has_heldout_tasks: bool) -> float:
        """``task_dropout``, with None resolved for a suite with or without held-out tasks."""
        if self.task_dropout is not None:
            return self.task_dropout
        return UNSEEN_TASK_DROPOUT if has_heldout_tasks else 0.0


UNSEEN_TASK_DROPOUT = 0.1
"""Task dropout of runs on suites with held-out tasks: one sample in ten trains the shared embedding."""


_LEROBOT_STUDENTS_PARSED: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "lerobot_students_parsed", default=True
)
"""Whether the option parser offers LeRobot's students (building it for them imports LeRobot and torch)."""


def names_lerobot_student(options: Sequence[str]) -> bool:
    """Whether the options may choose a student other than ``mtdagger`` (``UserError``: unknown type)."""
    for position, option in enumerate(options):
        name, separator, value = option.partition("=")
        if name == "--config_path":
            return True
        if name == "--policy.type":
            if not separator:
                value = options[position + 1] if position + 1 < len(options) else ""
            return check_student_name(value) != MTDAGGER_TYPE
    return False


@contextlib.contextmanager
def students_for(options: Sequence[str]) -> Iterator[None]:
    """Offers LeRobot's students to the parser only if ``options`` may name one (fast ``--help``)."""
    token = _LEROBOT_STUDENTS_PARSED.set(names_lerobot_student(options))
    try:
        yield
    finally:
        _LEROBOT_STUDENTS_PARSED.reset(token)


class StudentOptions:
    """The student policy and its options: ``--policy.type`` (draccus choice type; default ``mtdagger``).

    Each registered student gives its options class; a stored config without ``type`` is ``mtdagger``.
    """

    if TYPE_CHECKING:  # what every student's options hold once ``RunConfig`` has filled its preset
        batch_size: int
        device: str

    @classmethod
    def get_choice_class(cls, name: str) -> type:
        """The options class of a ``--policy.type``."""
        return cls.get_known_choices()[name]

    @classmethod
    def get_known_choices(cls) -> dict[str, type]:
        """Every ``--policy.type`` and its options class (``mtdagger`` alone unless ``students_for``)."""
        if not _LEROBOT_STUDENTS_PARSED.get():
            return {MTDAGGER_TYPE: PolicyOptions}  # the mtdagger student's options_class()
        return {name: get_student(name).options_class() for name in student_names()}

    @classmethod
    def get_choice_name(cls, subcls: type) -> str:
        """The ``--policy.type`` of an options class (``ValueError`` if it is no student's)."""
        for name, choice in cls.get_known_choices().items():
            if choice is subcls:
                return name
        raise ValueError(f"{subcls} is not a student policy's options class.")

    @classmethod
    def default_choice_name(cls) -> str:
        """``mtdagger``."""
        return MTDAGGER_TYPE


def student_type(options: Any) -> str:
    """The ``--policy.type`` of a run's policy options."""
    return student_of_options(options).name


def policy_options_dict(options: Any) -> dict[str, Any]:
    """JSON-ready policy options: ``mtdagger``'s fields alone (no ``type``), else ``type`` and its own."""
    return student_of_options(options).options_dict(options)
