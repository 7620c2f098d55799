"""The drawer expert's labels are a smooth function of the hand's position near the handle.

DAgger asks the expert about the learner's states, and a point-cloud learner localises the handle to
about a centimetre. An expert whose command flips from "descend" to "rise at full speed" on a few
millimetres of misalignment gives labels the learner cannot tell apart (measured: they made visual
DAgger rounds worse, ``experiments/visual-collapse-dev/README.md``). No MuJoCo here: states are built.
"""

from __future__ import annotations

import numpy as np
import pytest

from lerobot_mtdagger.envs.drawers.catalogue import VARIANTS
from lerobot_mtdagger.envs.drawers.variants import DRAWER_STATE_NAMES, STATE_INDEX
from lerobot_mtdagger.experts.drawers import (
    ALIGN_TOLERANCE,
    PAD_HALF_WIDTH,
    SAFE_HEIGHT,
    DrawerScriptedExpert,
)


def drawer_state(hand, grasp, yaw, gripper=1.0):
    state = np.zeros(len(DRAWER_STATE_NAMES))
    axis = np.array([np.sin(yaw), -np.cos(yaw), 0.0])
    for i, name in enumerate("xyz"):
        state[STATE_INDEX[f"hand_{name}"]] = hand[i]
        state[STATE_INDEX[f"grasp_{name}"]] = grasp[i]
        state[STATE_INDEX[f"axis_{name}"]] = axis[i]
    state[STATE_INDEX["gripper"]] = gripper
    state[STATE_INDEX["travel"]] = 0.15
    return state


def near_handle_states(rng, count):
    """Open-gripper hand positions within 3 cm of the grasp pose in the plane, up to 6 cm above it."""
    for _ in range(count):
        grasp = np.array([rng.uniform(-0.2, 0.2), rng.uniform(0.6, 0.7), rng.uniform(0.05, 0.2)])
        yaw = rng.uniform(-0.2, 0.2)
        hand = grasp + rng.uniform([-0.03, -0.03, -0.005], [0.03, 0.03, 0.06])
        yield hand, grasp, yaw


@pytest.fixture
def expert():
    return DrawerScriptedExpert(VARIANTS["drawer-bar-wide"])


def test_half_a_centimetre_changes_the_command_by_little(expert):
    """Measured: at most 0.34 here; the former expert's retreat rule changed it by up to 1.72."""
    rng = np.random.default_rng(0)
    for hand, grasp, yaw in near_handle_states(rng, 2000):
        shift = rng.normal(size=3) * np.array([1.0, 1.0, 0.0])
        shift *= 0.005 / np.linalg.norm(shift)
        before = expert.act(drawer_state(hand, grasp, yaw))
        after = expert.act(drawer_state(hand + shift, grasp, yaw))
        assert np.abs(before[:3] - after[:3]).max() < 0.5, (hand, grasp, yaw)


def test_a_centimetre_off_at_the_handle_is_corrected_in_place(expert):
    """Not a retreat to the safe height: the hand moves towards the grasp pose and rises a little
    (a centimetre along the pull axis, or beyond the closing range across it)."""
    grasp = np.array([0.0, 0.65, 0.1])
    sideways = expert.close_half_width + 0.012
    for offset in ([sideways, 0.0, 0.0], [0.0, 0.012, 0.0], [-0.008, -0.008, 0.0]):
        hand = grasp + np.array(offset)
        branch, action = expert.decide(drawer_state(hand, grasp, 0.0))
        assert action[3] < 0, "the gripper stays open while misaligned"
        assert np.dot(action[:2], (grasp - hand)[:2]) > 0, branch
        assert 0 < action[2] < 1, branch


@pytest.mark.parametrize("across", [True, False])
def test_the_funnel_height_is_continuous_and_bounded(expert, across):
    offsets = np.linspace(0, 0.2, 401)
    heights = [expert.clearance(x, 0.0) if across else expert.clearance(0.0, x) for x in offsets]
    assert heights[0] == 0.0 and expert.clearance(0.0, ALIGN_TOLERANCE) == 0.0
    assert expert.clearance(expert.close_half_width + ALIGN_TOLERANCE, 0.0) == 0.0
    assert max(heights) == SAFE_HEIGHT
    assert np.all(np.diff(heights) >= 0) and np.abs(np.diff(heights)).max() < 0.003


def test_an_open_hand_at_depth_a_centimetre_off_sideways_slides_over_without_rising():
    """The pads straddle a vertical bar: sideways at its depth they hit nothing, so the expert does not
    send the hand up (the former funnel did, 52% of a round-1 student's steps) but towards the bar."""
    expert = DrawerScriptedExpert(VARIANTS["drawer-vbar-tall"])
    grasp = np.array([0.0, 0.65, 0.1])
    for lateral in (0.01, 0.015, 0.02):
        branch, action = expert.decide(drawer_state(grasp + [lateral, 0, 0], grasp, 0.0))
        assert branch in ("descend", "grip") and action[0] < 0 and abs(action[2]) < 0.1, lateral


def test_aligned_at_depth_closes_and_a_closed_gripper_off_the_handle_opens(expert):
    grasp = np.array([0.0, 0.65, 0.1])
    branch, action = expert.decide(drawer_state(grasp + 0.002, grasp, 0.0))
    assert branch == "grip" and action[3] == 1.0
    branch, action = expert.decide(drawer_state(grasp + np.array([0.05, 0.0, 0.04]), grasp, 0.0, gripper=0.3))
    assert branch == "release" and action[3] == -1.0 and action[2] >= 0


def test_a_closed_gripper_that_overlaps_the_handle_holds_and_pulls():
    """1.7 cm off a vertical bar the pads still catch it (``test_envs_drawers``): pull, do not let go."""
    expert = DrawerScriptedExpert(VARIANTS["drawer-vbar-tall"])
    grasp = np.array([0.0, 0.65, 0.1])
    for lateral in (-0.017, 0.012, 0.017):
        branch, action = expert.decide(drawer_state(grasp + [lateral, 0, 0], grasp, 0.0, gripper=0.3))
        assert branch == "pull" and action[3] == 1.0 and action[1] < 0
    branch, _ = expert.decide(drawer_state(grasp + [0.03, 0, 0], grasp, 0.0, gripper=0.3))
    assert branch == "release"


def test_the_holding_range_grows_with_the_handle():
    widths = {name: DrawerScriptedExpert.holding_half_width(VARIANTS[name]) for name in VARIANTS}
    assert widths["drawer-vbar-tall"] < widths["drawer-knob-small"] < widths["drawer-bar-wide"]
    assert min(widths.values()) > 0.015


def test_the_closing_range_keeps_the_pads_off_a_bar_s_standoffs():
    for name, variant in VARIANTS.items():
        closing = DrawerScriptedExpert.closing_half_width(variant)
        assert ALIGN_TOLERANCE <= closing < DrawerScriptedExpert.holding_half_width(variant), name
        if variant.handle == "bar":
            assert closing + PAD_HALF_WIDTH < variant.free_gap_half_width(), name
