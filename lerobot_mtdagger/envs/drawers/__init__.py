"""A procedurally generated drawer-opening suite on MetaWorld's Sawyer arena (``docs/drawers.md``).

The paper opens 11 drawers in IsaacLab from point clouds and tests on an unseen one. Here each drawer
is a ``DrawerVariant`` turned into MJCF at run time and placed on MetaWorld's table (same arm, 4-d
action, cameras and renderer as the MetaWorld suites): a case and a drawer on a slide joint with a
``bar``, ``knob``, ``lip`` or ``vbar`` handle. Success: open by ``SUCCESS_FRACTION`` of the travel;
``info["progress"]`` is the paper's 0-3 real-robot score. Each reset places the case by the suite's
``placement`` (``PLACEMENTS``).

Modules: ``variants`` (``DrawerVariant``, constants, ``DRAWER_STATE_NAMES``), ``catalogue`` (the
drawers), ``mjcf`` (MJCF text), ``scene`` (the MuJoCo env), ``suite`` (``DrawerSuite``), ``pictures``.
The names a user needs are importable from here, lazily, so importing ``variants`` or ``catalogue``
(as the drawer expert does) loads neither MuJoCo nor MetaWorld.
"""

from __future__ import annotations

import importlib
from typing import Any

_EXPORTS: dict[str, str] = {
    "DRAWER_TASKS": "catalogue",
    "HELDOUT_TASKS": "catalogue",
    "DRAWER_STATE_NAMES": "variants",
    "PLACEMENTS": "variants",
    "SUCCESS_FRACTION": "variants",
    "DrawerVariant": "variants",
    "DrawerSuite": "suite",
}
"""Public name -> the submodule that defines it."""

__all__ = [
    "DRAWER_STATE_NAMES",
    "DRAWER_TASKS",
    "HELDOUT_TASKS",
    "PLACEMENTS",
    "SUCCESS_FRACTION",
    "DrawerSuite",
    "DrawerVariant",
]


def __getattr__(name: str) -> Any:
    """Imports the submodule that defines ``name`` on first access (PEP 562)."""
    module = _EXPORTS.get(name)
    if module is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f"{__name__}.{module}"), name)
    globals()[name] = value
    return value


def __dir__() -> list[str]:
    """The module's names and the lazily imported public ones."""
    return sorted(set(globals()) | set(_EXPORTS))
