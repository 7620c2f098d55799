"""The policy types a run's student may save (names only: reading it imports nothing heavy).

A student registered from outside the package adds its type with ``add_student_policy_type``.
"""

from __future__ import annotations

MTDAGGER_TYPE = "mtdagger"
"""The package's own policy: the default student."""

BUILTIN_STUDENT_TYPES: tuple[str, ...] = (MTDAGGER_TYPE, "act", "diffusion")
"""The students the package registers: ``mtdagger`` and LeRobot's ACT and Diffusion Policy."""

_EXTRA_POLICY_TYPES: list[str] = []


def add_student_policy_type(policy_type: str) -> None:
    """Accepts policy folders of ``policy_type`` (a student registered from outside the package)."""
    if policy_type not in BUILTIN_STUDENT_TYPES and policy_type not in _EXTRA_POLICY_TYPES:
        _EXTRA_POLICY_TYPES.append(policy_type)


def student_policy_types() -> tuple[str, ...]:
    """The LeRobot policy types of every registered student, the built-in ones first."""
    return (*BUILTIN_STUDENT_TYPES, *_EXTRA_POLICY_TYPES)
