"""The scripted expert of the drawer suite: a stateless controller on the privileged state.

It must label any state a learner reaches (DAgger asks it about the learner's states), so it keeps
no memory: each action follows from the privileged state alone (``DRAWER_STATE_NAMES``).

1. Gripper open, hand not above the grasp pose: rise to a safe height (``SAFE_HEIGHT`` above the
   grasp pose), move over the grasp pose, keeping the gripper open.
2. Gripper open and over the grasp pose: descend until the rear finger pad is behind the handle.
3. At the grasp pose: close the gripper (the rear pad pulls the handle into the grip).
4. Gripper closed on the handle: pull along the drawer's axis until it is open by
   ``OPEN_TARGET`` of its travel, correcting sideways and vertical drift; then hold.
5. Gripper closed anywhere else (a learner closed it, or the grip slipped): open it and back off
   upwards before approaching again.

The grasp pose comes from the env (``grasp_x/y/z``: the hand position that puts the open
gripper's rear pad behind the handle); it moves with the drawer, so the controller also recovers
from drawers a learner left half open.
"""

from __future__ import annotations

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


def _unpack(state: np.ndarray) -> dict[str, np.ndarray | float]:
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
        """Stores the drawer the expert opens (its geometry arrives through the privileged state)."""
        self.variant = variant

    def reset(self) -> None:
        """The expert is stateless."""

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """One action: end-effector displacement xyz (1 = 1 cm) and gripper effort (+1 closes)."""
        s = _unpack(np.asarray(privileged_state, dtype=np.float64))
        hand, grasp, axis = s["hand"], s["grasp"], s["axis"]
        lateral_axis = np.array([-axis[1], axis[0], 0.0])
        error = grasp - hand
        lateral = float(error @ lateral_axis)
        # > 0 when the hand is closer to the robot than the grasp pose (the handle was pulled into the grip).
        along = float((hand - grasp) @ axis)
        depth = float(error[2])
        at_depth = abs(depth) < 2 * DEPTH_TOLERANCE
        holding_zone = abs(lateral) < 0.015 and -0.05 < along < 0.015
        aligned = abs(lateral) < ALIGN_TOLERANCE and abs(along) < ALIGN_TOLERANCE

        if at_depth and holding_zone and (s["gripper"] < OPEN_GRIPPER or aligned):
            return self._grip_and_pull(s, lateral, lateral_axis, depth)
        if s["gripper"] < OPEN_GRIPPER:
            return self._release(hand, grasp)
        return self._approach(hand, grasp, aligned, depth)

    def _grip_and_pull(self, s: dict, lateral: float, lateral_axis: np.ndarray, depth: float) -> np.ndarray:
        correction = GAIN * (lateral * lateral_axis + np.array([0.0, 0.0, depth]))
        move = correction
        if s["gripper"] < CLOSED_GRIPPER and s["opening"] < OPEN_TARGET * s["travel"]:
            move = correction + PULL_SPEED * s["axis"]
        return self._action(move, grip=1.0)

    def _release(self, hand: np.ndarray, grasp: np.ndarray) -> np.ndarray:
        safe_z = grasp[2] + SAFE_HEIGHT
        move = np.array([0.0, 0.0, 1.0]) if hand[2] < safe_z else np.zeros(3)
        return self._action(move, grip=-1.0)

    def _approach(self, hand: np.ndarray, grasp: np.ndarray, aligned: bool, depth: float) -> np.ndarray:
        safe_z = grasp[2] + SAFE_HEIGHT
        if not aligned:
            if hand[2] < safe_z - 0.02 and np.linalg.norm((grasp - hand)[:2]) < 0.12:
                # Near the drawer and low: rise first, so the fingers clear the handle.
                return self._action(np.array([0.0, 0.0, 1.0]), grip=-1.0)
            target = np.array([grasp[0], grasp[1], max(hand[2], safe_z)])
            return self._action(GAIN * (target - hand), grip=-1.0)
        if abs(depth) >= DEPTH_TOLERANCE:
            return self._action(GAIN * (grasp - hand), grip=-1.0)
        return self._action(GAIN * (grasp - hand), grip=1.0)

    @staticmethod
    def _action(move: np.ndarray, grip: float) -> np.ndarray:
        return np.clip(np.append(move, grip), -1.0, 1.0).astype(np.float32)


def scripted_expert(suite: Any, task_name: str) -> DrawerScriptedExpert:
    """The registry's factory for the ``drawers`` suite family (``experts.registry``)."""
    return DrawerScriptedExpert(suite.variants[task_name])
