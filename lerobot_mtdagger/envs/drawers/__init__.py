"""A procedurally generated drawer-opening suite on MetaWorld's Sawyer arena.

The paper's third benchmark opens 11 drawers of different geometry and articulation in IsaacLab
(10 PartNet-Mobility models and one model of a real drawer) from point clouds, and tests on an
unseen drawer. Here each drawer is a ``DrawerVariant``, a small dataclass turned into MJCF at run
time and placed on MetaWorld's table in front of MetaWorld's Sawyer arm (same hand, mocap control,
4-d action, cameras and renderer as the MetaWorld suites).

A drawer is a static case (open-fronted box, optionally on a plinth) and a drawer box on a slide
joint along the case's pull axis, with an overlay front panel and one of four handles:

=======  ===================================================================================
bar      horizontal bar pull on two standoffs (``handle_size`` = bar length)
knob     round knob: a stem and a disc cap (``handle_size`` = cap radius)
lip      edge pull: a tab along the top edge of the front with a forward lip
         (``handle_size`` = tab width; ``handle_height`` must be 0, the tab sits on the edge)
vbar     vertical bar pull whose ends overhang its standoffs (``handle_size`` = bar length)
=======  ===================================================================================

Variants differ in handle type, size, height and clearance, drawer width/height/depth, travel,
joint damping and friction (``frictionloss``), case position and yaw on the table, plinth
elevation and colours. ``drawer-kitchen`` models a standard kitchen drawer (128 mm bar pull, 40 cm
wide front on a 10 cm plinth, 20 cm travel, stiffer runners) as the suite's "real" drawer.

Success: the drawer is open by at least ``SUCCESS_FRACTION`` (0.8) of its travel. ``info`` also
carries ``progress`` (0-3, the paper's real-robot score, kept as the best of the episode so far):
1 for touching the handle with the fingers, 1 for pulling it open by ``PULL_FRACTION`` (0.1) of
the travel, 1 for success. ``info["opening"]`` is the opening in metres.

Each reset places the case around the variant's pose by the suite's ``placement`` setting
(``PLACEMENTS``), drawn from the env's seeded generator; the drawer starts closed. ``kitchen`` (the
default): up to 10 cm across the table, 5 cm in depth, 12 degrees of yaw, 6 cm higher, and case,
front and handle colours shifted by up to 0.2 per RGB channel; ``narrow`` (the suite's first
setting): 3 cm in x and y, 5 degrees, fixed colours.

The privileged state (``DRAWER_STATE_NAMES``, what the scripted expert acts on and what
``observation.state`` is in ``state`` mode) holds the hand position and gripper opening, the
handle centre, the grasp pose of the hand (the hand position that puts the rear finger pad behind
the handle), the pull axis, the opening, the travel and the goal (the handle centre at the success
opening). In ``rgb`` and ``pointcloud`` modes ``observation.state`` is hand xyz + gripper opening
only: the drawer is in the image or cloud (``include_goal`` has no effect on this suite).

Modules, one job each (dependencies flow one way; ``variants`` and ``catalogue`` themselves import
neither MuJoCo, MetaWorld nor gymnasium):

===============  ==================================================================================
``variants``     ``DrawerVariant`` and its validation; success/pull fractions, placement range,
                 episode length, table limits; ``DRAWER_STATE_NAMES`` and ``STATE_INDEX``
``catalogue``    the drawers: ``TRAINING_DRAWERS``, ``HELDOUT_DRAWERS``, ``DRAWER_TASKS``,
                 ``HELDOUT_TASKS``, ``VARIANTS``
``mjcf``         MJCF generation (``drawer_body_xml``, ``drawer_mjcf``)
``scene``        ``DrawerSceneEnv``, the raw MuJoCo/MetaWorld env
``suite``        ``DrawerTaskEnv``, ``DrawerSuite``, ``DRAWER_CROP``, ``drawer_state_names``
``pictures``     ``render_drawer_picture``
===============  ==================================================================================

The names a user of the suite needs are importable from here too (``DrawerSuite``,
``DrawerVariant``, ``DRAWER_TASKS``, ``HELDOUT_TASKS``, ``PLACEMENTS``, ``DRAWER_STATE_NAMES``,
``SUCCESS_FRACTION``), lazily: a name's module is imported on first access, so importing ``variants``
or ``catalogue`` (as the drawer expert does) loads neither the MuJoCo scene nor MetaWorld. Every other
name is imported from the module that defines it.
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
