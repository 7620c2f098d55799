"""A procedurally generated drawer-opening suite on MetaWorld's Sawyer arena (``docs/drawers.md``).

Each drawer is a ``DrawerVariant`` turned into MJCF at run time: a case and a drawer on a slide joint
with a ``bar``, ``knob``, ``lip`` or ``vbar`` handle, placed on MetaWorld's table by the suite's
``placement``. Success: open by ``SUCCESS_FRACTION`` of the travel; ``info["progress"]`` is the paper's
0-3 score. Modules: ``variants``, ``catalogue``, ``mjcf``, ``scene``, ``suite``, ``pictures``. The
names a user needs are importable from here, lazily, so ``variants`` and ``catalogue`` (which the
drawer expert imports) load neither MuJoCo nor MetaWorld.
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
