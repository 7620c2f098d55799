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

Every public name is re-exported here (``from lerobot_mtdagger.envs.drawers import DrawerSuite``),
lazily: a name's module is imported on first access, so importing ``variants`` or ``catalogue``
(as the drawer expert does) loads neither the MuJoCo scene nor MetaWorld.
"""

from __future__ import annotations

import importlib
from typing import TYPE_CHECKING, Any

# Public name (all of ``__all__``) -> the submodule that defines it.
_EXPORTS: dict[str, str] = {
    **dict.fromkeys(
        ("DRAWER_TASKS", "HELDOUT_DRAWERS", "HELDOUT_TASKS", "TRAINING_DRAWERS", "VARIANTS"), "catalogue"
    ),
    **dict.fromkeys(("PAD_HALF_HEIGHT", "PAD_OFFSET_Y", "drawer_body_xml", "drawer_mjcf"), "mjcf"),
    "render_drawer_picture": "pictures",
    "DrawerSceneEnv": "scene",
    **dict.fromkeys(("DRAWER_CROP", "DrawerSuite", "DrawerTaskEnv", "drawer_state_names"), "suite"),
    **dict.fromkeys(
        (
            "DRAWER_STATE_NAMES",
            "HANDLE_TYPES",
            "MAX_EPISODE_STEPS",
            "DEFAULT_PLACEMENT",
            "PLACEMENTS",
            "PLACEMENT_RANGE",
            "PULL_FRACTION",
            "STATE_INDEX",
            "SUCCESS_FRACTION",
            "TABLE_X_LIMIT",
            "TABLE_Y_RANGE",
            "DrawerVariant",
            "Placement",
            "placement_named",
        ),
        "variants",
    ),
}

if TYPE_CHECKING:
    from lerobot_mtdagger.envs.drawers.catalogue import (
        DRAWER_TASKS,
        HELDOUT_DRAWERS,
        HELDOUT_TASKS,
        TRAINING_DRAWERS,
        VARIANTS,
    )
    from lerobot_mtdagger.envs.drawers.mjcf import PAD_HALF_HEIGHT, PAD_OFFSET_Y, drawer_body_xml, drawer_mjcf
    from lerobot_mtdagger.envs.drawers.pictures import render_drawer_picture
    from lerobot_mtdagger.envs.drawers.scene import DrawerSceneEnv
    from lerobot_mtdagger.envs.drawers.suite import (
        DRAWER_CROP,
        DrawerSuite,
        DrawerTaskEnv,
        drawer_state_names,
    )
    from lerobot_mtdagger.envs.drawers.variants import (
        DEFAULT_PLACEMENT,
        DRAWER_STATE_NAMES,
        HANDLE_TYPES,
        MAX_EPISODE_STEPS,
        PLACEMENT_RANGE,
        PLACEMENTS,
        PULL_FRACTION,
        STATE_INDEX,
        SUCCESS_FRACTION,
        TABLE_X_LIMIT,
        TABLE_Y_RANGE,
        DrawerVariant,
        Placement,
        placement_named,
    )

__all__ = [
    "DEFAULT_PLACEMENT",
    "DRAWER_CROP",
    "DRAWER_STATE_NAMES",
    "DRAWER_TASKS",
    "HANDLE_TYPES",
    "HELDOUT_DRAWERS",
    "HELDOUT_TASKS",
    "MAX_EPISODE_STEPS",
    "PAD_HALF_HEIGHT",
    "PAD_OFFSET_Y",
    "PLACEMENTS",
    "PLACEMENT_RANGE",
    "PULL_FRACTION",
    "STATE_INDEX",
    "SUCCESS_FRACTION",
    "TABLE_X_LIMIT",
    "TABLE_Y_RANGE",
    "TRAINING_DRAWERS",
    "VARIANTS",
    "DrawerSceneEnv",
    "DrawerSuite",
    "DrawerTaskEnv",
    "DrawerVariant",
    "Placement",
    "drawer_body_xml",
    "drawer_mjcf",
    "drawer_state_names",
    "placement_named",
    "render_drawer_picture",
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
    return sorted(set(globals()) | set(_EXPORTS))
