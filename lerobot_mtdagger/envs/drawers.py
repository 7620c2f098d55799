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

Each reset shifts the case by up to ``PLACEMENT_RANGE`` (3 cm in x and y, 5 degrees of yaw) from
the variant's pose, drawn from the env's seeded generator; the drawer starts closed.

The privileged state (``DRAWER_STATE_NAMES``, what the scripted expert acts on and what
``observation.state`` is in ``state`` mode) holds the hand position and gripper opening, the
handle centre, the grasp pose of the hand (the hand position that puts the rear finger pad behind
the handle), the pull axis, the opening, the travel and the goal (the handle centre at the success
opening). In ``rgb`` and ``pointcloud`` modes ``observation.state`` is hand xyz + gripper opening
only: the drawer is in the image or cloud (``include_goal`` has no effect on this suite).
"""

from __future__ import annotations

import functools
import logging
import math
import os
import tempfile
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium.envs.mujoco import MujocoEnv
from metaworld.sawyer_xyz_env import SawyerXYZEnv

from lerobot_mtdagger.envs.base import ObservationConfig, TaskSuite, observation_features
from lerobot_mtdagger.envs.metaworld import ACTION_DIM, ACTION_NAMES, PROPRIO_NAMES, MetaWorldTaskEnv
from lerobot_mtdagger.envs.rendering import CropBox
from lerobot_mtdagger.experts import Expert

logger = logging.getLogger(__name__)

HANDLE_TYPES: tuple[str, ...] = ("bar", "knob", "lip", "vbar")
SUCCESS_FRACTION = 0.8
PULL_FRACTION = 0.1
PLACEMENT_RANGE = (0.03, 0.03, 5.0)  # +- x (m), +- y (m), +- yaw (degrees) per reset
MAX_EPISODE_STEPS = 300

# MetaWorld's open gripper holds its finger pads 4.7 cm either side of the hand along world y; the
# rear pad (+y, away from the robot) goes behind the handle.
PAD_OFFSET_Y = 0.047
PAD_HALF_HEIGHT = 0.045

# The table top is z = 0, x in [-0.7, 0.7]; MetaWorld's retaining walls stand at y = 0.21 and 0.99.
TABLE_X_LIMIT = 0.62
TABLE_Y_RANGE = (0.45, 0.985)
DRAWER_CROP = CropBox(low=(-0.62, 0.3, 0.005), high=(0.62, 0.975, 0.55))

DRAWER_STATE_NAMES: list[str] = [
    "hand_x",
    "hand_y",
    "hand_z",
    "gripper",
    "handle_x",
    "handle_y",
    "handle_z",
    "grasp_x",
    "grasp_y",
    "grasp_z",
    "axis_x",
    "axis_y",
    "axis_z",
    "opening",
    "travel",
    "goal_x",
    "goal_y",
    "goal_z",
]
STATE_INDEX = {name: i for i, name in enumerate(DRAWER_STATE_NAMES)}

_WALL = 0.01  # case wall thickness
_FRONT = 0.015  # front panel thickness
_GAP = 0.004  # clearance between drawer box and case
_STANDOFF_RADIUS = 0.005
_BAR_RADIUS = 0.007
_KNOB_STEM_RADIUS = 0.005
_KNOB_CAP_THICKNESS = 0.012
_VBAR_OVERHANG = 0.03
_LIP_TAB_HEIGHT = 0.035
_LIP_THICKNESS = 0.004
_LIP_OVERHANG = 0.012
_FINGER_MARGIN = 0.005


def _check(condition: bool, message: str) -> None:
    if not condition:
        raise ValueError(message)


@dataclass(frozen=True)
class DrawerVariant:
    """One procedurally generated drawer. Lengths in metres, angles in degrees.

    Attributes:
        name: Task name, ``drawer-<handle>-<what sets it apart>``.
        handle: ``bar``, ``knob``, ``lip`` or ``vbar``.
        handle_size: Bar length (bar, vbar), cap radius (knob) or tab width (lip).
        handle_height: Height of the handle centre on the front, as a fraction of half the front
            height (-1 bottom edge, 0 centre, 1 top edge); must be 0 for ``lip``.
        handle_clearance: Gap between the front panel and the back of the handle (finger room);
            unused by ``lip`` (its tab stands flush on the top edge; the finger goes behind it).
        width: Outer width of the case.
        height: Outer height of the case.
        depth: Outer depth of the case.
        travel: How far the drawer slides open.
        damping: Viscous damping of the slide joint, N s/m.
        friction: Dry friction of the slide joint (MuJoCo ``frictionloss``), N.
        x: Case front centre, world x (the table spans about -0.6 .. 0.6).
        y: Case front centre, world y (the case extends from here away from the robot).
        yaw: Case rotation about the vertical axis; 0 faces the robot.
        elevation: Height of a plinth under the case (0: the case stands on the table).
        case_rgba: Case colour.
        front_rgba: Front panel colour.
        handle_rgba: Handle colour.
    """

    name: str
    handle: str
    handle_size: float
    handle_height: float
    handle_clearance: float
    width: float
    height: float
    depth: float
    travel: float
    damping: float
    friction: float
    x: float
    y: float
    yaw: float
    elevation: float = 0.0
    case_rgba: tuple[float, float, float, float] = (0.55, 0.42, 0.3, 1.0)
    front_rgba: tuple[float, float, float, float] = (0.75, 0.6, 0.42, 1.0)
    handle_rgba: tuple[float, float, float, float] = (0.7, 0.7, 0.72, 1.0)

    def __post_init__(self) -> None:
        where = f"DrawerVariant {self.name!r}"
        _check(
            self.name.startswith("drawer-"),
            f"{where}: task names start with 'drawer-' (got {self.name!r}).",
        )
        _check(
            self.handle in HANDLE_TYPES,
            f"{where}: handle must be one of {HANDLE_TYPES}, got {self.handle!r}.",
        )
        for field in ("handle_size", "handle_clearance", "width", "height", "depth"):
            value = getattr(self, field)
            _check(
                math.isfinite(value) and value > 0,
                f"{where}: {field} must be a positive length in metres, got {value}.",
            )
        _check(
            math.isfinite(self.travel) and self.travel > 0,
            f"{where}: travel must be > 0 (a drawer that cannot move cannot be opened), got {self.travel}.",
        )
        _check(
            self.travel <= 0.8 * self.depth,
            f"{where}: travel {self.travel} m exceeds 0.8 x depth ({0.8 * self.depth:.3f} m); "
            "make the case deeper or the travel shorter.",
        )
        for field in ("damping", "friction", "elevation"):
            value = getattr(self, field)
            _check(math.isfinite(value) and value >= 0, f"{where}: {field} must be >= 0, got {value}.")
        _check(
            -1.0 < self.handle_height < 1.0,
            f"{where}: handle_height must be in (-1, 1), got {self.handle_height}.",
        )
        _check(
            self.handle != "lip" or self.handle_height == 0.0,
            f"{where}: a lip handle sits on the top edge; set handle_height=0 (got {self.handle_height}).",
        )
        _check(abs(self.yaw) <= 30.0, f"{where}: yaw must be within +-30 degrees, got {self.yaw}.")
        for field in ("case_rgba", "front_rgba", "handle_rgba"):
            color = getattr(self, field)
            _check(
                len(color) == 4 and all(0.0 <= c <= 1.0 for c in color),
                f"{where}: {field} must be 4 numbers in [0, 1], got {color}.",
            )
        self._check_handle_fits(where)
        self._check_on_table(where)

    def _check_handle_fits(self, where: str) -> None:
        pad_room = 2 * 0.004 + 2 * _FINGER_MARGIN
        _check(
            self.handle_clearance >= pad_room,
            f"{where}: handle_clearance {self.handle_clearance} m leaves no room for a finger; "
            f"use >= {pad_room}.",
        )
        _check(self.width >= 0.12, f"{where}: width must be >= 0.12 m, got {self.width}.")
        _check(self.height >= 0.06, f"{where}: height must be >= 0.06 m, got {self.height}.")
        _check(self.depth >= 0.12, f"{where}: depth must be >= 0.12 m, got {self.depth}.")
        low, high = self.handle_extent_z()
        front_low, front_high = self.elevation + 0.003, self.elevation + self.height - 0.003
        if self.handle in ("bar", "lip"):
            _check(
                0.08 <= self.handle_size <= self.width - 0.02,
                f"{where}: a {self.handle} handle needs handle_size in [0.08, width - 0.02], "
                f"got {self.handle_size}.",
            )
        if self.handle == "knob":
            _check(
                0.018 <= self.handle_size <= 0.04,
                f"{where}: a knob's cap radius (handle_size) must be in [0.018, 0.04] m, "
                f"got {self.handle_size}.",
            )
        if self.handle == "vbar":
            _check(
                self.handle_size >= 2 * _VBAR_OVERHANG + 0.02,
                f"{where}: a vbar needs handle_size >= {2 * _VBAR_OVERHANG + 0.02} m, "
                f"got {self.handle_size}.",
            )
        if self.handle != "lip":
            _check(
                front_low <= low and high <= front_high,
                f"{where}: the handle spans z {low:.3f}..{high:.3f} m, outside the front "
                f"({front_low:.3f}..{front_high:.3f}); move handle_height towards 0 or shrink handle_size.",
            )

    def _check_on_table(self, where: str) -> None:
        corners = self.case_corners_xy()
        _check(
            bool(np.all(np.abs(corners[:, 0]) <= TABLE_X_LIMIT)),
            f"{where}: the case reaches x = {np.abs(corners[:, 0]).max():.3f} m, off the table "
            f"(|x| <= {TABLE_X_LIMIT}); move x towards 0 or narrow the case.",
        )
        _check(
            bool(np.all((corners[:, 1] >= TABLE_Y_RANGE[0]) & (corners[:, 1] <= TABLE_Y_RANGE[1]))),
            f"{where}: the case spans y {corners[:, 1].min():.3f}..{corners[:, 1].max():.3f} m, outside "
            f"{TABLE_Y_RANGE} (MetaWorld's back wall stands at 0.99); move y or make the case shallower.",
        )

    def case_corners_xy(self) -> np.ndarray:
        """World (x, y) of the four footprint corners of the case at the variant's nominal pose, (4, 2)."""
        half = self.width / 2
        local = np.array([[-half, 0.0], [half, 0.0], [-half, self.depth], [half, self.depth]])
        yaw = math.radians(self.yaw)
        rotation = np.array([[math.cos(yaw), -math.sin(yaw)], [math.sin(yaw), math.cos(yaw)]])
        return local @ rotation.T + np.array([self.x, self.y])

    def handle_center_z(self) -> float:
        """Height of the handle centre above the case bottom (case frame, without elevation)."""
        if self.handle == "lip":
            return self.height + _LIP_TAB_HEIGHT / 2 - 0.003
        return self.height / 2 + self.handle_height * (self.height / 2 - 0.003)

    def handle_extent_z(self) -> tuple[float, float]:
        """World z range of the handle at the nominal pose."""
        center = self.elevation + self.handle_center_z()
        half = {
            "bar": _BAR_RADIUS,
            "knob": self.handle_size,
            "lip": _LIP_TAB_HEIGHT / 2,
            "vbar": self.handle_size / 2 + _BAR_RADIUS,
        }[self.handle]
        return center - half, center + half

    def parameter_vector(self) -> np.ndarray:
        """Numeric description (handle one-hot, then every geometric and physical parameter)."""
        one_hot = [float(self.handle == h) for h in HANDLE_TYPES]
        numbers = [
            self.handle_size,
            self.handle_height,
            self.handle_clearance,
            self.width,
            self.height,
            self.depth,
            self.travel,
            self.damping,
            self.friction,
            self.x,
            self.y,
            self.yaw,
            self.elevation,
        ]
        return np.asarray(one_hot + numbers + list(self.front_rgba), dtype=np.float64)


TRAINING_DRAWERS: tuple[DrawerVariant, ...] = (
    DrawerVariant(
        "drawer-bar-wide", "bar", 0.16, 0.0, 0.03, 0.34, 0.14, 0.2, 0.15, 2.0, 0.5, -0.05, 0.78, 0.0,
    ),
    DrawerVariant(
        "drawer-bar-narrow", "bar", 0.09, 0.3, 0.025, 0.18, 0.12, 0.2, 0.12, 4.0, 1.0, 0.12, 0.765, 8.0,
        front_rgba=(0.2, 0.3, 0.55, 1.0), case_rgba=(0.15, 0.2, 0.35, 1.0),
    ),
    DrawerVariant(
        "drawer-bar-low", "bar", 0.12, -0.5, 0.03, 0.26, 0.2, 0.2, 0.13, 3.0, 0.5, -0.14, 0.77, -6.0,
        front_rgba=(0.85, 0.85, 0.8, 1.0), case_rgba=(0.6, 0.6, 0.58, 1.0), handle_rgba=(0.1, 0.1, 0.1, 1.0),
    ),
    DrawerVariant(
        "drawer-knob-small", "knob", 0.022, 0.0, 0.028, 0.2, 0.11, 0.18, 0.1, 1.5, 0.3, 0.0, 0.8, 0.0,
        elevation=0.04, front_rgba=(0.8, 0.3, 0.25, 1.0), handle_rgba=(0.9, 0.85, 0.6, 1.0),
    ),
    DrawerVariant(
        "drawer-knob-large", "knob", 0.03, 0.3, 0.032, 0.3, 0.16, 0.2, 0.14, 5.0, 1.5, 0.13, 0.755, -10.0,
        front_rgba=(0.35, 0.5, 0.3, 1.0), case_rgba=(0.3, 0.35, 0.25, 1.0),
    ),
    DrawerVariant(
        "drawer-knob-deep", "knob", 0.026, -0.2, 0.03, 0.24, 0.13, 0.26, 0.2, 2.0, 0.5, -0.1, 0.7, 5.0,
        front_rgba=(0.9, 0.75, 0.35, 1.0), handle_rgba=(0.25, 0.2, 0.15, 1.0),
    ),
    DrawerVariant(
        "drawer-lip-wide", "lip", 0.2, 0.0, 0.03, 0.36, 0.12, 0.2, 0.14, 2.0, 0.5, 0.0, 0.78, 0.0,
        front_rgba=(0.95, 0.95, 0.95, 1.0), case_rgba=(0.8, 0.8, 0.8, 1.0),
        handle_rgba=(0.55, 0.55, 0.6, 1.0),
    ),
    DrawerVariant(
        "drawer-lip-shallow", "lip", 0.1, 0.0, 0.03, 0.22, 0.08, 0.18, 0.1, 1.0, 0.2, 0.12, 0.78, 7.0,
        elevation=0.06, front_rgba=(0.3, 0.3, 0.32, 1.0), case_rgba=(0.2, 0.2, 0.22, 1.0),
    ),
    DrawerVariant(
        "drawer-vbar-tall", "vbar", 0.12, 0.0, 0.03, 0.2, 0.22, 0.2, 0.14, 3.0, 0.8, -0.12, 0.78, 0.0,
        front_rgba=(0.5, 0.25, 0.2, 1.0), handle_rgba=(0.85, 0.7, 0.3, 1.0),
    ),
    DrawerVariant(
        "drawer-vbar-stiff", "vbar", 0.1, 0.15, 0.028, 0.24, 0.16, 0.2, 0.12, 12.0, 3.0, 0.1, 0.765, -5.0,
        front_rgba=(0.4, 0.45, 0.5, 1.0), case_rgba=(0.25, 0.27, 0.3, 1.0),
    ),
    DrawerVariant(
        "drawer-kitchen", "bar", 0.128, 0.0, 0.032, 0.4, 0.15, 0.28, 0.2, 8.0, 2.0, 0.0, 0.7, 0.0,
        elevation=0.1, front_rgba=(0.96, 0.96, 0.94, 1.0), case_rgba=(0.62, 0.48, 0.33, 1.0),
        handle_rgba=(0.6, 0.6, 0.62, 1.0),
    ),
)  # fmt: skip

HELDOUT_DRAWERS: tuple[DrawerVariant, ...] = (
    DrawerVariant(
        "drawer-bar-angled", "bar", 0.1, -0.2, 0.027, 0.28, 0.13, 0.2, 0.13, 6.0, 1.0, 0.15, 0.75, 15.0,
        elevation=0.02, front_rgba=(0.6, 0.2, 0.45, 1.0), case_rgba=(0.35, 0.15, 0.3, 1.0),
    ),
    DrawerVariant(
        "drawer-knob-tall", "knob", 0.024, 0.5, 0.03, 0.22, 0.2, 0.2, 0.12, 3.0, 1.0, -0.15, 0.76, -12.0,
        front_rgba=(0.3, 0.6, 0.65, 1.0), handle_rgba=(0.2, 0.2, 0.2, 1.0),
    ),
    DrawerVariant(
        "drawer-vbar-short", "vbar", 0.08, 0.0, 0.026, 0.18, 0.14, 0.18, 0.1, 2.0, 0.4, 0.05, 0.78, 10.0,
        elevation=0.08, front_rgba=(0.9, 0.55, 0.2, 1.0),
    ),
    DrawerVariant(
        "drawer-lip-heavy", "lip", 0.14, 0.0, 0.03, 0.26, 0.1, 0.22, 0.16, 10.0, 2.5, -0.1, 0.74, -8.0,
        elevation=0.03, front_rgba=(0.45, 0.35, 0.6, 1.0), case_rgba=(0.3, 0.25, 0.4, 1.0),
    ),
)  # fmt: skip

DRAWER_TASKS: tuple[str, ...] = tuple(v.name for v in TRAINING_DRAWERS)
HELDOUT_TASKS: tuple[str, ...] = tuple(v.name for v in HELDOUT_DRAWERS)
VARIANTS: dict[str, DrawerVariant] = {v.name: v for v in TRAINING_DRAWERS + HELDOUT_DRAWERS}


# -------------------------------------------------------------------------------------------------
# MJCF
# -------------------------------------------------------------------------------------------------


def _vec(values: Sequence[float]) -> str:
    return " ".join(f"{v:.5g}" for v in values)


def _box(name: str, pos: Sequence[float], size: Sequence[float], rgba: Sequence[float]) -> str:
    return f'<geom name="{name}" type="box" pos="{_vec(pos)}" size="{_vec(size)}" rgba="{_vec(rgba)}"/>'


def _round_geom(
    kind: str, name: str, start: Sequence[float], end: Sequence[float], radius: float, rgba: Sequence[float]
) -> str:
    """A ``capsule`` or ``cylinder`` handle part from ``start`` to ``end`` (grippy: friction 1.5)."""
    return (
        f'<geom name="{name}" type="{kind}" fromto="{_vec([*start, *end])}" size="{radius:.5g}" '
        f'rgba="{_vec(rgba)}" friction="1.5 0.05 0.001" condim="4"/>'
    )


_capsule = functools.partial(_round_geom, "capsule")
_cylinder = functools.partial(_round_geom, "cylinder")


def _case_geoms(v: DrawerVariant) -> list[str]:
    w, h, d, t = v.width, v.height, v.depth, _WALL
    rgba = v.case_rgba
    geoms = [
        _box("case_bottom", (0, d / 2, t / 2), (w / 2, d / 2, t / 2), rgba),
        _box("case_top", (0, d / 2, h - t / 2), (w / 2, d / 2, t / 2), rgba),
        _box("case_left", (-(w / 2 - t / 2), d / 2, h / 2), (t / 2, d / 2, h / 2), rgba),
        _box("case_right", (w / 2 - t / 2, d / 2, h / 2), (t / 2, d / 2, h / 2), rgba),
        _box("case_back", (0, d - t / 2, h / 2), (w / 2 - t, t / 2, h / 2 - t), rgba),
    ]
    if v.elevation > 0:
        plinth = (w / 2 - 0.01, d / 2 - 0.01, v.elevation / 2)
        geoms.append(_box("case_plinth", (0, d / 2 + 0.01, -v.elevation / 2), plinth, rgba))
    return geoms


def _drawer_geoms(v: DrawerVariant) -> list[str]:
    w, h, d, t = v.width, v.height, v.depth, _WALL
    inner_w = w - 2 * t - 2 * _GAP
    inner_d = d - t - 2 * _GAP
    side_h = 0.6 * (h - 2 * t - 2 * _GAP)
    floor_z = t + _GAP + 0.004
    center_y = inner_d / 2 + _GAP
    side_x, side_z, back_y = inner_w / 2 - 0.004, floor_z + side_h / 2, center_y + inner_d / 2 - 0.004
    rgba = v.front_rgba
    body = tuple(0.85 * c for c in rgba[:3]) + (1.0,)
    return [
        _box("drawer_front", (0, -_FRONT / 2, h / 2), (w / 2 - 0.002, _FRONT / 2, h / 2 - 0.002), rgba),
        _box("drawer_floor", (0, center_y, floor_z), (inner_w / 2, inner_d / 2, 0.004), body),
        _box("drawer_left", (-side_x, center_y, side_z), (0.004, inner_d / 2, side_h / 2), body),
        _box("drawer_right", (side_x, center_y, side_z), (0.004, inner_d / 2, side_h / 2), body),
        _box("drawer_back", (0, back_y, side_z), (inner_w / 2, 0.004, side_h / 2), body),
    ]  # fmt: skip


def _handle_geoms(v: DrawerVariant) -> tuple[list[str], np.ndarray, np.ndarray]:
    """Handle geoms in the drawer frame, the handle centre and the rear finger pad's hook point."""
    rgba = v.handle_rgba
    z = v.handle_center_z()
    front = -_FRONT  # y of the front face
    c = v.handle_clearance
    if v.handle == "bar":
        y = front - c - _BAR_RADIUS
        half = v.handle_size / 2
        post_x = half - 0.012
        geoms = [
            _capsule("handle_bar", (-half, y, z), (half, y, z), _BAR_RADIUS, rgba),
            _cylinder("handle_post_left", (-post_x, front, z), (-post_x, y, z), _STANDOFF_RADIUS, rgba),
            _cylinder("handle_post_right", (post_x, front, z), (post_x, y, z), _STANDOFF_RADIUS, rgba),
        ]
        hook = np.array([0.0, front - c / 2, z + 0.02])
        return geoms, np.array([0.0, y, z]), hook
    if v.handle == "vbar":
        y = front - c - _BAR_RADIUS
        half = v.handle_size / 2
        post_z = half - _VBAR_OVERHANG
        geoms = [
            _capsule("handle_bar", (0, y, z - half), (0, y, z + half), _BAR_RADIUS, rgba),
            _cylinder("handle_post_top", (0, front, z + post_z), (0, y, z + post_z), _STANDOFF_RADIUS, rgba),
            _cylinder(
                "handle_post_bottom", (0, front, z - post_z), (0, y, z - post_z), _STANDOFF_RADIUS, rgba
            ),
        ]
        pad_bottom = z + post_z + _STANDOFF_RADIUS + _FINGER_MARGIN
        hook = np.array([0.0, front - c / 2, pad_bottom + PAD_HALF_HEIGHT])
        return geoms, np.array([0.0, y, z]), hook
    if v.handle == "knob":
        cap_back = front - c
        geoms = [
            _cylinder("handle_stem", (0, front, z), (0, cap_back, z), _KNOB_STEM_RADIUS, rgba),
            _cylinder(
                "handle_cap", (0, cap_back, z), (0, cap_back - _KNOB_CAP_THICKNESS, z), v.handle_size, rgba
            ),
        ]
        pad_bottom = z + _KNOB_STEM_RADIUS + _FINGER_MARGIN
        hook = np.array([0.0, front - c / 2, pad_bottom + PAD_HALF_HEIGHT])
        return geoms, np.array([0.0, cap_back - _KNOB_CAP_THICKNESS / 2, z]), hook
    # lip: a tab standing on the top edge of the front, flush with the front face, with a forward lip.
    half = v.handle_size / 2
    tab_y = front + _LIP_THICKNESS / 2
    top = v.height - 0.003 + _LIP_TAB_HEIGHT
    geoms = [
        _box("handle_tab", (0, tab_y, z), (half, _LIP_THICKNESS / 2, _LIP_TAB_HEIGHT / 2), rgba),
        _box(
            "handle_lip",
            (0, front - _LIP_OVERHANG / 2, top - _LIP_THICKNESS / 2),
            (half, _LIP_OVERHANG / 2, _LIP_THICKNESS / 2),
            rgba,
        ),
    ]
    pad_bottom = v.height + _FINGER_MARGIN
    hook = np.array([0.0, front + _LIP_THICKNESS + 0.004 + _FINGER_MARGIN, pad_bottom + PAD_HALF_HEIGHT])
    return geoms, np.array([0.0, tab_y, z]), hook


def drawer_body_xml(v: DrawerVariant) -> str:
    """The ``<body>`` of the case, the drawer, its joint, handle and sites (MJCF fragment)."""
    handle_geoms, handle_center, hook = _handle_geoms(v)
    # MetaWorld's compiler takes inertia from geom groups 4-5 only: the drawer gets explicit inertia,
    # about 0.8 kg for a 30 x 20 cm drawer, scaled with its footprint.
    mass = 0.8 * (v.width * v.depth) / (0.3 * 0.2)
    extent = np.array([v.width, v.depth, v.height])
    inertia = mass / 12.0 * (extent[[1, 0, 0]] ** 2 + extent[[2, 2, 1]] ** 2)
    yaw = math.radians(v.yaw)
    quat = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    case = "\n        ".join(_case_geoms(v))
    drawer = "\n            ".join(_drawer_geoms(v) + handle_geoms)
    return f"""
    <body name="drawer_case" childclass="drawer_part" pos="{_vec((v.x, v.y, v.elevation))}"
          quat="{_vec(quat)}">
        {case}
        <body name="drawer" pos="0 0 0">
            <joint name="drawer_slide" type="slide" axis="0 -1 0" range="0 {v.travel:.5g}" limited="true"
                   damping="{v.damping:.5g}" frictionloss="{v.friction:.5g}" armature="0.01"/>
            <inertial pos="{_vec((0, v.depth / 2, v.height / 2))}" mass="{mass:.5g}"
                      diaginertia="{_vec(inertia)}"/>
            {drawer}
            <site name="handle" pos="{_vec(handle_center)}" size="0.005" rgba="0 0 0 0" group="5"/>
            <site name="hook" pos="{_vec(hook)}" size="0.005" rgba="0 0 0 0" group="5"/>
        </body>
    </body>"""


def drawer_mjcf(v: DrawerVariant) -> str:
    """The complete MJCF of MetaWorld's arena with the drawer of ``v``.

    Includes MetaWorld's scene, arm and gripper (``../scene``, ``../objects`` relative to the file,
    which ``DrawerSceneEnv`` writes next to links to MetaWorld's asset folders).
    """
    return f"""<mujoco model="{v.name}">
    <include file="../scene/basic_scene.xml"/>
    <include file="../objects/assets/xyz_base_dependencies.xml"/>
    <default>
        <default class="drawer_part">
            <geom density="400" condim="3" solref="0.01 1"/>
        </default>
    </default>
    <worldbody>
        <include file="../objects/assets/xyz_base.xml"/>
        {drawer_body_xml(v)}
        <site name="goal" pos="0 0.6 0.2" size="0.01" rgba="0 0 0 0" group="5"/>
    </worldbody>
    <contact>
        <exclude body1="drawer_case" body2="drawer"/>
        <exclude body1="RetainingWall" body2="drawer"/>
    </contact>
    <actuator>
        <position ctrllimited="true" ctrlrange="-1 1" joint="r_close" kp="400" user="1"/>
        <position ctrllimited="true" ctrlrange="-1 1" joint="l_close" kp="400" user="1"/>
    </actuator>
    <equality>
        <weld body1="mocap" body2="hand" solref="0.02 1"/>
    </equality>
</mujoco>
"""


def _metaworld_assets() -> Path:
    import metaworld

    return Path(metaworld.__file__).parent / "assets"


class DrawerSceneEnv(SawyerXYZEnv):
    """MetaWorld's Sawyer arena with one procedurally generated drawer (raw, array observations).

    The MJCF is written to a temporary folder that links MetaWorld's asset folders (its includes
    are relative), compiled, and deleted again.
    """

    max_path_length = MAX_EPISODE_STEPS

    def __init__(self, variant: DrawerVariant) -> None:
        """Builds the model of ``variant``."""
        self.variant = variant
        self._tmp = tempfile.TemporaryDirectory(prefix="mtdagger-drawer-")
        root = Path(self._tmp.name)
        assets = _metaworld_assets()
        for folder in ("scene", "objects", "textures"):
            os.symlink(assets / folder, root / folder)
        (root / "sawyer_xyz").mkdir()
        self._model_path = str(root / "sawyer_xyz" / f"{variant.name}.xml")
        Path(self._model_path).write_text(drawer_mjcf(variant))
        try:
            super().__init__(hand_low=(-0.5, 0.36, 0.05), hand_high=(0.5, 1.0, 0.5))
        finally:
            self._tmp.cleanup()
        self._partially_observable = False
        self._freeze_rand_vec = False
        self.seeded_rand_vec = True
        self._set_task_called = True
        self.hand_init_pos = np.array([0.0, 0.55, 0.25])
        self.init_tcp = self.tcp_center
        self._random_reset_space = gym.spaces.Box(
            -np.asarray(PLACEMENT_RANGE), np.asarray(PLACEMENT_RANGE), dtype=np.float64
        )
        self.goal_space = gym.spaces.Box(np.full(3, -np.inf), np.full(3, np.inf), dtype=np.float64)
        self._joint_qpos = self.model.jnt_qposadr[self.model.joint("drawer_slide").id]
        self._pad_geoms = {self.model.geom(n).id for n in ("leftpad_geom", "rightpad_geom")}
        self._pad_geoms |= {self.model.geom(n).id for n in ("leftclaw_it", "rightclaw_it")}
        self._handle_geoms = {
            i for i in range(self.model.ngeom) if (self.model.geom(i).name or "").startswith("handle_")
        }
        self._progress = 0
        self._target_pos = np.zeros(3)

    @property
    def model_name(self) -> str:
        """Path of the generated MJCF (exists only while the model compiles)."""
        return self._model_path

    @property
    def sawyer_observation_space(self) -> gym.spaces.Box:  # type: ignore[override]
        """Unbounded box of the privileged state (``DRAWER_STATE_NAMES``)."""
        size = len(DRAWER_STATE_NAMES)
        return gym.spaces.Box(np.full(size, -np.inf), np.full(size, np.inf), dtype=np.float64)

    # -- geometry --------------------------------------------------------------------------------

    @property
    def opening(self) -> float:
        """How far the drawer is open, metres."""
        return float(self.data.qpos[self._joint_qpos])

    def pull_axis(self) -> np.ndarray:
        """Unit vector of the opening direction in the world."""
        return self.data.body("drawer_case").xmat.reshape(3, 3) @ np.array([0.0, -1.0, 0.0])

    def handle_position(self) -> np.ndarray:
        """World position of the handle centre."""
        return self.data.site("handle").xpos.copy()

    def grasp_position(self) -> np.ndarray:
        """Hand position that puts the open gripper's rear pad behind the handle."""
        return self.data.site("hook").xpos - np.array([0.0, PAD_OFFSET_Y, 0.0])

    def goal_position(self) -> np.ndarray:
        """Handle centre at the success opening."""
        remaining = SUCCESS_FRACTION * self.variant.travel - self.opening
        return self.handle_position() + remaining * self.pull_axis()

    def handle_distance(self, points: np.ndarray) -> np.ndarray:
        """Distance of each world point (N, 3+) to the nearest handle surface (0 inside), (N,)."""
        return self.surface_distance(points, sorted(self._handle_geoms))

    def surface_distance(self, points: np.ndarray, geoms: Sequence[int | str]) -> np.ndarray:
        """Distance of each world point (N, 3+) to the nearest of some box/capsule/cylinder geoms, (N,).

        Raises:
            ValueError: On a geom of another type.
        """
        points = np.asarray(points, dtype=np.float64)[:, :3]
        distances = np.full(points.shape[0], np.inf)
        for geom in (self.model.geom(g).id for g in geoms):
            local = (points - self.data.geom_xpos[geom]) @ self.data.geom_xmat[geom].reshape(3, 3)
            size = self.model.geom_size[geom]
            kind = self.model.geom_type[geom]
            if kind == mujoco.mjtGeom.mjGEOM_BOX:
                outside = np.maximum(np.abs(local) - size, 0.0)
            elif kind == mujoco.mjtGeom.mjGEOM_CAPSULE:
                axial = np.clip(local[:, 2], -size[1], size[1])
                radial = np.linalg.norm(local - np.stack([0 * axial, 0 * axial, axial], axis=1), axis=1)
                outside = np.maximum(radial - size[0], 0.0)[:, None]
            elif kind == mujoco.mjtGeom.mjGEOM_CYLINDER:
                radial = np.linalg.norm(local[:, :2], axis=1) - size[0]
                axial = np.abs(local[:, 2]) - size[1]
                outside = np.maximum(np.stack([radial, axial], axis=1), 0.0)
            else:
                raise ValueError(f"surface_distance handles boxes, capsules and cylinders, not geom {geom}.")
            distances = np.minimum(distances, np.linalg.norm(outside, axis=1))
        return distances

    def fingers_touch_handle(self) -> bool:
        """Whether a finger pad or claw touches a handle geom."""
        for contact in self.data.contact[: self.data.ncon]:
            pair = {int(contact.geom1), int(contact.geom2)}
            if pair & self._pad_geoms and pair & self._handle_geoms:
                return True
        return False

    # -- MetaWorld hooks -------------------------------------------------------------------------

    def _get_pos_objects(self) -> np.ndarray:
        return self.data.site("handle").xpos.copy()

    def _get_quat_objects(self) -> np.ndarray:
        return self.data.body("drawer_case").xquat.copy()

    def _get_obs(self) -> np.ndarray:
        hand_and_gripper = self._get_curr_obs_combined_no_goal()[:4]
        return np.concatenate(
            [
                hand_and_gripper,
                self.handle_position(),
                self.grasp_position(),
                self.pull_axis(),
                [self.opening, self.variant.travel],
                self.goal_position(),
            ]
        )

    def reset_model(self) -> np.ndarray:
        """Places the case (seeded offsets around the variant's pose), closes the drawer, homes the hand."""
        offset = self._get_state_rand_vec()
        v = self.variant
        self.model.body("drawer_case").pos = (v.x + offset[0], v.y + offset[1], v.elevation)
        yaw = math.radians(v.yaw + offset[2])
        self.model.body("drawer_case").quat = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        self.data.qpos[self._joint_qpos] = 0.0
        self.data.qvel[self.model.jnt_dofadr[self.model.joint("drawer_slide").id]] = 0.0
        mujoco.mj_forward(self.model, self.data)
        self._reset_hand()
        self._progress = 0
        self._target_pos = self.goal_position()
        return self._get_obs()

    def reset(
        self, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict]:
        """Resets the scene (the seed is set through ``seed()``, as in MetaWorld)."""
        self.curr_path_length = 0
        obs, info = MujocoEnv.reset(self)
        return obs.astype(np.float64), info

    def evaluate_state(self, obs: np.ndarray, action: np.ndarray) -> tuple[float, dict[str, Any]]:
        """Success, progress (0-3, best so far) and a dense reward (reach + opening)."""
        travel = self.variant.travel
        opening = self.opening
        success = opening >= SUCCESS_FRACTION * travel
        touched = self.fingers_touch_handle()
        pulled = opening >= PULL_FRACTION * travel
        progress = int(touched or pulled) + int(pulled) + int(success)
        self._progress = max(self._progress, progress)
        reach = float(np.linalg.norm(obs[0:3] - obs[7:10]))
        reward = (1.0 - math.tanh(5.0 * reach)) + 5.0 * min(opening / travel, 1.0)
        info = {
            "success": float(success),
            "progress": self._progress,
            "opening": opening,
            "touching_handle": float(touched),
        }
        return reward, info


def drawer_state_names(config: ObservationConfig) -> list[str]:
    """Names of ``observation.state``: privileged state in ``state`` mode, else hand xyz + gripper."""
    return DRAWER_STATE_NAMES if config.obs_mode == "state" else PROPRIO_NAMES


def render_drawer_picture(
    variant: DrawerVariant, height: int = 240, width: int = 320, opening_fraction: float = 0.5
) -> np.ndarray:
    """A picture of a drawer (half open by default) seen from the robot's side, (H, W, 3) uint8.

    Args:
        variant: The drawer.
        height: Picture height in pixels (<= 480).
        width: Picture width in pixels (<= 640).
        opening_fraction: How far the drawer is drawn open, as a fraction of its travel.

    Raises:
        ValueError: If ``opening_fraction`` is outside [0, 1].
    """
    if not 0.0 <= opening_fraction <= 1.0:
        raise ValueError(f"opening_fraction must be in [0, 1], got {opening_fraction}.")
    env = DrawerSceneEnv(variant)
    try:
        env.seed(0)
        env._freeze_rand_vec = True
        env._last_rand_vec = np.zeros(3)
        env.hand_init_pos = np.array([-0.45, 0.4, 0.45])  # out of the picture
        env.reset()
        env.data.qpos[env._joint_qpos] = opening_fraction * variant.travel
        mujoco.mj_forward(env.model, env.data)
        camera = mujoco.MjvCamera()
        camera.type = mujoco.mjtCamera.mjCAMERA_FREE
        camera.lookat[:] = (variant.x, variant.y + variant.depth / 3, variant.elevation + variant.height / 2)
        camera.distance = 0.45 + variant.width
        camera.azimuth, camera.elevation = 115.0, -30.0
        renderer = mujoco.Renderer(env.model, height, width)
        try:
            renderer.update_scene(env.data, camera=camera)
            return renderer.render().copy()
        finally:
            renderer.close()
    finally:
        env.close()


class DrawerTaskEnv(MetaWorldTaskEnv):
    """One drawer with LeRobot-keyed observations (see the module docstring)."""

    default_crop = DRAWER_CROP

    def __init__(
        self,
        variant: DrawerVariant,
        observation: ObservationConfig,
        seed: int | None = None,
        max_episode_steps: int | None = None,
    ) -> None:
        """Builds the drawer's model and env."""
        self.variant = variant
        super().__init__(variant.name, observation, seed=seed, max_episode_steps=max_episode_steps)

    def _build_raw_env(self) -> DrawerSceneEnv:
        return DrawerSceneEnv(self.variant)

    def state_names(self) -> list[str]:
        """Privileged state names in ``state`` mode, hand xyz + gripper otherwise."""
        return drawer_state_names(self.observation_config)

    def _proprio_state(self, raw: np.ndarray) -> np.ndarray:
        return raw[:4]

    def _step_info(self, raw: np.ndarray, raw_info: dict[str, Any]) -> dict[str, Any]:
        info = super()._step_info(raw, raw_info)
        info["progress"] = int(raw_info.get("progress", 0))
        info["opening"] = float(raw[STATE_INDEX["opening"]])
        return info


class DrawerSuite(TaskSuite):
    """The drawer-opening suite: 11 training drawers, held-out drawers for evaluation."""

    name = "drawers"

    def __init__(
        self,
        task_names: Sequence[str],
        observation: ObservationConfig,
        max_episode_steps: int | None = None,
        variants: Sequence[DrawerVariant] | None = None,
    ) -> None:
        """Selects the drawers of the suite.

        Args:
            task_names: Training drawers (any of ``DRAWER_TASKS`` and ``HELDOUT_TASKS``, or the
                names of ``variants``).
            observation: What the envs show the policy.
            max_episode_steps: Truncation length (``MAX_EPISODE_STEPS`` when None).
            variants: Extra drawer variants (user-defined) that task names may refer to.

        Raises:
            ValueError: On an unknown drawer.
        """
        self.variants = dict(VARIANTS)
        for variant in variants or ():
            self.variants[variant.name] = variant
        unknown = [t for t in task_names if t not in self.variants]
        if unknown:
            raise ValueError(f"Unknown drawer(s) {unknown}; known drawers: {sorted(self.variants)}.")
        super().__init__(task_names, observation)
        self.max_episode_steps = max_episode_steps
        self.heldout_task_names = [t for t in HELDOUT_TASKS if t not in self.task_names]

    @property
    def action_dim(self) -> int:
        """MetaWorld's 4-d action: end-effector displacement xyz and gripper effort."""
        return ACTION_DIM

    def make_env(self, task_name: str, seed: int | None = None) -> DrawerTaskEnv:
        """Builds the env of a training or held-out drawer."""
        self.check_buildable(task_name)
        variant = self.variants[task_name]
        return DrawerTaskEnv(variant, self.observation, seed=seed, max_episode_steps=self.max_episode_steps)

    def _scripted_expert(self, task_name: str) -> Expert:
        from lerobot_mtdagger.experts.drawers import DrawerScriptedExpert

        return DrawerScriptedExpert(self.variants[task_name])

    @property
    def features(self) -> dict[str, dict[str, Any]]:
        """LeRobot features of the observations of the current mode, plus ``action``."""
        return observation_features(self.observation, drawer_state_names(self.observation), ACTION_NAMES)
