"""MJCF generation: a ``DrawerVariant`` turned into the model of MetaWorld's arena with that drawer.

Pure string building, no MuJoCo import (``scene.py`` compiles the result).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Iterable, Sequence

import numpy as np

from lerobot_mtdagger.envs.drawers.variants import (
    BAR_POST_INSET,
    BAR_RADIUS,
    FINGER_MARGIN,
    LIP_TAB_HEIGHT,
    STANDOFF_RADIUS,
    VBAR_OVERHANG,
    DrawerVariant,
)

# MetaWorld's open gripper holds its finger pads 4.7 cm either side of the hand along world y; the
# rear pad (+y, away from the robot) goes behind the handle.
PAD_OFFSET_Y = 0.047
PAD_HALF_HEIGHT = 0.045

_WALL = 0.01  # case wall thickness
_FRONT = 0.015  # front panel thickness
_GAP = 0.004  # clearance between drawer box and case
_KNOB_STEM_RADIUS = 0.005
_KNOB_CAP_THICKNESS = 0.012
_LIP_THICKNESS = 0.004
_LIP_OVERHANG = 0.012


def _vec(values: Iterable[float]) -> str:
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


def _case_geoms(v: DrawerVariant, lift: float = 0.0) -> list[str]:
    """The case; its plinth reaches ``lift`` further down (below the table until a reset lifts it)."""
    w, h, d, t = v.width, v.height, v.depth, _WALL
    rgba = v.case_rgba
    geoms = [
        _box("case_bottom", (0, d / 2, t / 2), (w / 2, d / 2, t / 2), rgba),
        _box("case_top", (0, d / 2, h - t / 2), (w / 2, d / 2, t / 2), rgba),
        _box("case_left", (-(w / 2 - t / 2), d / 2, h / 2), (t / 2, d / 2, h / 2), rgba),
        _box("case_right", (w / 2 - t / 2, d / 2, h / 2), (t / 2, d / 2, h / 2), rgba),
        _box("case_back", (0, d - t / 2, h / 2), (w / 2 - t, t / 2, h / 2 - t), rgba),
    ]
    plinth_height = v.elevation + lift
    if plinth_height > 0:
        plinth = (w / 2 - 0.01, d / 2 - 0.01, plinth_height / 2)
        geoms.append(_box("case_plinth", (0, d / 2 + 0.01, -plinth_height / 2), plinth, rgba))
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
        y = front - c - BAR_RADIUS
        half = v.handle_size / 2
        post_x = half - BAR_POST_INSET
        geoms = [
            _capsule("handle_bar", (-half, y, z), (half, y, z), BAR_RADIUS, rgba),
            _cylinder("handle_post_left", (-post_x, front, z), (-post_x, y, z), STANDOFF_RADIUS, rgba),
            _cylinder("handle_post_right", (post_x, front, z), (post_x, y, z), STANDOFF_RADIUS, rgba),
        ]
        hook = np.array([0.0, front - c / 2, z + 0.02])
        return geoms, np.array([0.0, y, z]), hook
    if v.handle == "vbar":
        y = front - c - BAR_RADIUS
        half = v.handle_size / 2
        post_z = half - VBAR_OVERHANG
        geoms = [
            _capsule("handle_bar", (0, y, z - half), (0, y, z + half), BAR_RADIUS, rgba),
            _cylinder("handle_post_top", (0, front, z + post_z), (0, y, z + post_z), STANDOFF_RADIUS, rgba),
            _cylinder(
                "handle_post_bottom", (0, front, z - post_z), (0, y, z - post_z), STANDOFF_RADIUS, rgba
            ),
        ]
        pad_bottom = z + post_z + STANDOFF_RADIUS + FINGER_MARGIN
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
        pad_bottom = z + _KNOB_STEM_RADIUS + FINGER_MARGIN
        hook = np.array([0.0, front - c / 2, pad_bottom + PAD_HALF_HEIGHT])
        return geoms, np.array([0.0, cap_back - _KNOB_CAP_THICKNESS / 2, z]), hook
    # lip: a tab standing on the top edge of the front, flush with the front face, with a forward lip.
    half = v.handle_size / 2
    tab_y = front + _LIP_THICKNESS / 2
    top = v.height - 0.003 + LIP_TAB_HEIGHT
    geoms = [
        _box("handle_tab", (0, tab_y, z), (half, _LIP_THICKNESS / 2, LIP_TAB_HEIGHT / 2), rgba),
        _box(
            "handle_lip",
            (0, front - _LIP_OVERHANG / 2, top - _LIP_THICKNESS / 2),
            (half, _LIP_OVERHANG / 2, _LIP_THICKNESS / 2),
            rgba,
        ),
    ]
    pad_bottom = v.height + FINGER_MARGIN
    hook = np.array([0.0, front + _LIP_THICKNESS + 0.004 + FINGER_MARGIN, pad_bottom + PAD_HALF_HEIGHT])
    return geoms, np.array([0.0, tab_y, z]), hook


def drawer_body_xml(v: DrawerVariant, lift: float = 0.0) -> str:
    """The case, the drawer, its joint, handle and sites (MJCF ``<body>``); the plinth is ``lift`` longer."""
    handle_geoms, handle_center, hook = _handle_geoms(v)
    # MetaWorld's compiler takes inertia from geom groups 4-5 only: the drawer gets explicit inertia,
    # about 0.8 kg for a 30 x 20 cm drawer, scaled with its footprint.
    mass = 0.8 * (v.width * v.depth) / (0.3 * 0.2)
    extent = np.array([v.width, v.depth, v.height])
    inertia = mass / 12.0 * (extent[[1, 0, 0]] ** 2 + extent[[2, 2, 1]] ** 2)
    yaw = math.radians(v.yaw)
    quat = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
    case = "\n        ".join(_case_geoms(v, lift))
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


def drawer_mjcf(v: DrawerVariant, lift: float = 0.0) -> str:
    """The complete MJCF of MetaWorld's arena with the drawer of ``v`` (``lift`` as in ``drawer_body_xml``).

    Its includes are relative (``../scene``, ``../objects``): ``DrawerSceneEnv`` writes the file next to
    links to MetaWorld's asset folders.
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
        {drawer_body_xml(v, lift)}
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
