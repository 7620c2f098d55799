"""The options of LeRobot's students (``act``, ``diffusion``): LeRobot's own config of the policy.

The parser offers them only when ``--policy.type`` names such a student; options ``run`` cannot
honour are refused (``UNSUPPORTED_STUDENT_OPTIONS``).
"""

from __future__ import annotations

import dataclasses
import functools
from dataclasses import field
from typing import Any

from lerobot_mtdagger.datasets.student_types import BUILTIN_STUDENT_TYPES, MTDAGGER_TYPE


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


def lerobot_policy_config(options: Any) -> Any:
    """The plain LeRobot config of a LeRobot student's options (without ``batch_size``)."""
    base = type(options).__mro__[1]
    values = {f.name: getattr(options, f.name) for f in dataclasses.fields(base) if f.init}
    return base(**values)
