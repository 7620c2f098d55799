"""The student's options, ``--policy.*``: ``mtdagger``'s own (``PolicyOptions``) or a LeRobot policy's.

``--policy.type`` chooses the student (``StudentOptions``, over the students registered in
``runner.student``); LeRobot's students (``act``, ``diffusion``) take LeRobot's own config of that
policy plus ``batch_size``, offered by the parser only when the options name a student other than
``mtdagger`` (``students_for``), so a run of ``mtdagger`` never imports them.
"""

from __future__ import annotations

import contextlib
import contextvars
import dataclasses
import functools
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from lerobot_mtdagger.datasets.student_types import BUILTIN_STUDENT_TYPES, MTDAGGER_TYPE
from lerobot_mtdagger.runner.student import get_student, student_names, student_of_options


@dataclass
class PolicyOptions:
    """Options of the ``mtdagger`` policy and its training (None: from the preset).

    Attributes:
        batch_size: Training batch size.
        lr: AdamW learning rate.
        state_hidden_dims: Hidden sizes of the state MLP.
        head_hidden_dims: Hidden sizes of the action head.
        pointnet_dims: PointNet per-point MLP sizes.
        pointnet_layer_norm: LayerNorm after every PointNet layer and its projection (DP3's encoder;
            with ``pointcloud_embedding_dim=64`` and 512 points, DP3's size).
        pointcloud_embedding_dim: Output size of the point-cloud encoder.
        task_embedding_dim: Task embedding size.
        task_dropout: Probability of training a sample on the shared "any task" embedding instead of
            its own (``MTDAggerConfig.task_dropout``: what lets the policy act on unseen tasks). None:
            ``UNSEEN_TASK_DROPOUT`` for a suite with held-out tasks (the drawers), else 0.
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


def _lerobot_student(config_class: type) -> type:
    """``config_class`` (a LeRobot policy config) with the run's training batch size added.

    Every option is LeRobot's own (``--policy.type=act --policy.chunk_size=20``); the learning rate
    is the policy's ``optimizer_lr`` (its optimiser preset), so a preset's ``policy.lr`` does not
    apply. Defaults that differ from LeRobot's: ``device=cpu`` (as ``mtdagger``), ``push_to_hub=False``
    (``push`` uploads), and no pretrained vision backbone (nothing is downloaded during a run; pass
    ``--policy.pretrained_backbone_weights=...`` where the weights are cached).
    """
    extra: list[tuple[str, Any, Any]] = [
        ("batch_size", int | None, field(default=None)),
        ("device", str | None, field(default="cpu")),
        ("push_to_hub", bool, field(default=False)),
    ]
    if any(f.name == "pretrained_backbone_weights" for f in dataclasses.fields(config_class)):
        extra.append(("pretrained_backbone_weights", str | None, field(default=None)))
    student = dataclasses.make_dataclass(f"{config_class.__name__}Student", extra, bases=(config_class,))
    student.__doc__ = f"{config_class.__doc__ or config_class.__name__}\n\n{_lerobot_student.__doc__}"
    return student


UNSUPPORTED_STUDENT_OPTIONS: dict[str, str] = {
    "use_amp": "its training, collection and evaluation run in float32 (lerobot-eval honours it for a "
    "saved policy)",
    "use_peft": "the student is trained in full",
    "push_to_hub": "`lerobot-mtdagger push` uploads a run's rounds and policies",
    "pretrained_path": "each phase starts from the previous phase's policy (training.warm_start) or afresh",
}
"""Options of LeRobot's policy configs that ``run`` would otherwise ignore: refused, naming why."""


@functools.cache
def lerobot_options_class(policy_type: str) -> type:
    """The options class of a LeRobot policy type as a student (LeRobot's policies imported on first use)."""
    import lerobot.policies  # noqa: F401  (registers LeRobot's policy configs)
    from lerobot.configs.policies import PreTrainedConfig

    return _lerobot_student(PreTrainedConfig.get_choice_class(policy_type))


def lerobot_students() -> dict[str, type]:
    """The options class of each built-in LeRobot student type (every one but ``mtdagger``)."""
    return {name: lerobot_options_class(name) for name in BUILTIN_STUDENT_TYPES if name != MTDAGGER_TYPE}


_LEROBOT_STUDENTS_PARSED: contextvars.ContextVar[bool] = contextvars.ContextVar(
    "lerobot_students_parsed", default=True
)
"""Whether the option parser offers LeRobot's students (building it for them imports LeRobot and torch)."""


def names_lerobot_student(options: Sequence[str]) -> bool:
    """Whether command-line options may choose a student other than ``mtdagger`` (a LeRobot one).

    They may with a registered ``--policy.type`` other than ``mtdagger``, or a ``--config_path`` file.

    Raises:
        UserError: If ``--policy.type`` names no registered student (one line listing them).
    """
    for position, option in enumerate(options):
        name, separator, value = option.partition("=")
        if name == "--config_path":
            return True
        if name == "--policy.type":
            if not separator:
                value = options[position + 1] if position + 1 < len(options) else ""
            return get_student(value).name != MTDAGGER_TYPE
    return False


@contextlib.contextmanager
def students_for(options: Sequence[str]) -> Iterator[None]:
    """Offers LeRobot's students to the parser only if ``options`` may name one.

    ``--help`` and a refused option then answer without importing LeRobot and torch (seconds on a
    small machine).
    """
    token = _LEROBOT_STUDENTS_PARSED.set(names_lerobot_student(options))
    try:
        yield
    finally:
        _LEROBOT_STUDENTS_PARSED.reset(token)


class StudentOptions:
    """The student policy and its options: ``--policy.type`` (draccus choice type; default ``mtdagger``).

    Each registered student (``runner.student``) gives its options class: ``mtdagger`` takes
    ``PolicyOptions``; ``act`` and ``diffusion`` take LeRobot's own config of that policy
    (``lerobot_students()``) plus ``batch_size``. A stored config without ``type`` is ``mtdagger``.
    """

    @classmethod
    def get_choice_class(cls, name: str) -> type:
        """The options class of a ``--policy.type``."""
        return cls.get_known_choices()[name]

    @classmethod
    def get_known_choices(cls) -> dict[str, type]:
        """Every ``--policy.type`` and its options class.

        ``mtdagger`` alone while options that name no other student are parsed (``students_for``).
        """
        if not _LEROBOT_STUDENTS_PARSED.get():
            return {MTDAGGER_TYPE: get_student(MTDAGGER_TYPE).options_class()}
        return {name: get_student(name).options_class() for name in student_names()}

    @classmethod
    def get_choice_name(cls, subcls: type) -> str:
        """The ``--policy.type`` of an options class.

        Raises:
            ValueError: If ``subcls`` is not a student's options class.
        """
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


def lerobot_policy_config(options: Any) -> Any:
    """The plain LeRobot config of a LeRobot student's options (without ``batch_size``)."""
    base = type(options).__mro__[1]
    values = {f.name: getattr(options, f.name) for f in dataclasses.fields(base) if f.init}
    return base(**values)


def policy_options_dict(options: Any) -> dict[str, Any]:
    """JSON-ready policy options: ``mtdagger``'s fields as before (no ``type``), else type + its own."""
    return student_of_options(options).options_dict(options)
