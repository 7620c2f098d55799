"""The scripted expert of the drawer suite: a stateless controller on the privileged state.

It labels any state a learner reaches, so each action follows from ``DRAWER_STATE_NAMES`` alone.

1. Gripper open: servo towards a target above the grasp pose whose height grows with the planar
   misalignment (``clearance``): a funnel ending at the grasp pose. A hand more than ``RISE_FIRST``
   below the funnel rises before it moves sideways.
2. At the grasp pose, within the closing range across the pull axis: close the gripper.
3. Closed on the handle (within ``hold_half_width``): pull along the drawer's axis until it is open
   by ``OPEN_TARGET`` of its travel, correcting drift; then hold.
4. Closed anywhere else: open, rising to the funnel's height, and approach again.

The command is continuous in the hand's position except for the gripper's open/close decision, so
a learner that localises the handle to a centimetre gets consistent labels. The grasp pose comes from
the env and moves with the drawer, so the controller also recovers from half-open drawers.
See ``docs/drawers.md`` (Scripted experts) for the ranges and how they were measured.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from lerobot_mtdagger.envs.drawers.variants import STATE_INDEX, DrawerVariant

SAFE_HEIGHT = 0.08
OPEN_TARGET = 0.95
GAIN = 12.0
PULL_SPEED = 0.8
OPEN_GRIPPER = 0.9  # gripper reading (finger distance / 10 cm) above which the gripper counts as open
CLOSED_GRIPPER = 0.75  # below which it holds something (or nothing) closed
ALIGN_TOLERANCE = 0.008
DEPTH_TOLERANCE = 0.012
PAD_HALF_WIDTH = 0.015  # MetaWorld's finger pad: a box 3 cm wide across the pull axis
HOLD_MARGIN = 0.003  # inside the catch range by this much before a closed gripper counts as holding
CLOSE_MARGIN = 0.004  # inside the holding range by this much before the expert closes
HOLD_ALONG = (-0.05, 0.015)  # hand behind (pulled) / in front of the grasp pose along the axis while holding
FUNNEL_SLOPE = 4.0  # metres of height above the grasp pose per metre of planar misalignment
RISE_FIRST = 0.02  # below the funnel by more than this, the hand rises before it moves sideways
BRANCHES = ("align", "clear", "descend", "grip", "pull", "release")
"""What ``decide`` reports: move over the grasp pose at a safe height, rise to clear the handle, descend
onto the grasp pose, close on the handle (or hold it closed), pull, open the gripper and back off."""


def _unpack(state: np.ndarray) -> dict[str, Any]:
    def vec(prefix: str) -> np.ndarray:
        return np.array([state[STATE_INDEX[f"{prefix}_{axis}"]] for axis in "xyz"])

    return {
        "hand": vec("hand"),
        "gripper": float(state[STATE_INDEX["gripper"]]),
        "grasp": vec("grasp"),
        "axis": vec("axis"),
        "opening": float(state[STATE_INDEX["opening"]]),
        "travel": float(state[STATE_INDEX["travel"]]),
    }


class DrawerScriptedExpert:
    """Opens one drawer from any state (see the module docstring)."""

    def __init__(self, variant: DrawerVariant) -> None:
        """Stores the drawer the expert opens (its pose arrives through the privileged state)."""
        self.variant = variant
        self.hold_half_width = self.holding_half_width(variant)
        self.close_half_width = self.closing_half_width(variant)

    @staticmethod
    def holding_half_width(variant: DrawerVariant) -> float:
        """How far across the pull axis a closed gripper still holds the handle (the pads overlap it)."""
        return variant.handle_half_width() + PAD_HALF_WIDTH - HOLD_MARGIN

    @classmethod
    def closing_half_width(cls, variant: DrawerVariant) -> float:
        """How far across the pull axis the expert closes: inside the holding range and a bar's standoffs."""
        free = variant.free_gap_half_width() - PAD_HALF_WIDTH
        return max(ALIGN_TOLERANCE, min(cls.holding_half_width(variant), free) - CLOSE_MARGIN)

    def reset(self) -> None:
        """The expert is stateless."""

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """One action: end-effector displacement xyz (1 = 1 cm) and gripper effort (+1 closes)."""
        return self.decide(privileged_state)[1]

    def decide(self, privileged_state: np.ndarray) -> tuple[str, np.ndarray]:
        """The branch of the controller that acts (one of ``BRANCHES``) and its action."""
        s = _unpack(np.asarray(privileged_state, dtype=np.float64))
        hand, grasp, axis = s["hand"], s["grasp"], s["axis"]
        lateral_axis = np.array([-axis[1], axis[0], 0.0])
        error = grasp - hand
        lateral = float(error @ lateral_axis)
        # > 0 when the hand is closer to the robot than the grasp pose (the handle was pulled into the grip).
        along = float((hand - grasp) @ axis)
        depth = float(error[2])
        at_depth = abs(depth) < 2 * DEPTH_TOLERANCE
        holding_zone = abs(lateral) < self.hold_half_width and HOLD_ALONG[0] < along < HOLD_ALONG[1]
        aligned = abs(lateral) < self.close_half_width and abs(along) < ALIGN_TOLERANCE

        if at_depth and holding_zone and (s["gripper"] < OPEN_GRIPPER or aligned):
            return self._grip_and_pull(s, lateral, lateral_axis, depth)
        if s["gripper"] < OPEN_GRIPPER:
            return "release", self._release(hand, grasp, lateral, along)
        return self._approach(hand, grasp, lateral, along)

    def _grip_and_pull(
        self, s: dict, lateral: float, lateral_axis: np.ndarray, depth: float
    ) -> tuple[str, np.ndarray]:
        correction = GAIN * (lateral * lateral_axis + np.array([0.0, 0.0, depth]))
        if s["gripper"] < CLOSED_GRIPPER and s["opening"] < OPEN_TARGET * s["travel"]:
            return "pull", self._action(correction + PULL_SPEED * s["axis"], grip=1.0)
        return "grip", self._action(correction, grip=1.0)

    def clearance(self, lateral: float, along: float) -> float:
        """Height above the grasp pose the hand keeps at a planar misalignment (the approach funnel).

        0 within ``ALIGN_TOLERANCE`` along the axis and the closing range across it, then ``FUNNEL_SLOPE``
        metres per metre, at most ``SAFE_HEIGHT``.
        """
        across = max(0.0, abs(lateral) - self.close_half_width)
        planar = math.hypot(across, along)
        return min(SAFE_HEIGHT, FUNNEL_SLOPE * max(0.0, planar - ALIGN_TOLERANCE))

    def _release(self, hand: np.ndarray, grasp: np.ndarray, lateral: float, along: float) -> np.ndarray:
        target_z = grasp[2] + self.clearance(lateral, along)
        return self._action(np.array([0.0, 0.0, max(0.0, GAIN * (target_z - hand[2]))]), grip=-1.0)

    def _approach(
        self, hand: np.ndarray, grasp: np.ndarray, lateral: float, along: float
    ) -> tuple[str, np.ndarray]:
        clearance = self.clearance(lateral, along)
        target = grasp + np.array([0.0, 0.0, clearance])
        below = target[2] - hand[2]
        # Further below the funnel than RISE_FIRST: rise only (the fingers clear the handle first);
        # within it, blend the planar correction in.
        planar_weight = float(np.clip(1.0 - below / RISE_FIRST, 0.0, 1.0))
        move = GAIN * (target - hand)
        move[:2] *= planar_weight
        branch = "clear" if planar_weight < 1.0 else ("descend" if clearance == 0.0 else "align")
        return branch, self._action(move, grip=-1.0)

    @staticmethod
    def _action(move: np.ndarray, grip: float) -> np.ndarray:
        return np.clip(np.append(move, grip), -1.0, 1.0).astype(np.float32)


def scripted_expert(suite: Any, task_name: str) -> DrawerScriptedExpert:
    """The registry's factory for the ``drawers`` suite family (``experts.registry``)."""
    return DrawerScriptedExpert(suite.variants[task_name])
