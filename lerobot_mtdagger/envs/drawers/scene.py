"""The raw MuJoCo env: MetaWorld's Sawyer arena with one drawer (``DrawerSceneEnv``).

Places the case on each reset and computes the privileged state, success, progress and reward;
``suite.py`` turns its array observations into LeRobot-keyed dicts.
"""

from __future__ import annotations

import math
import os
import tempfile
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import gymnasium as gym
import mujoco
import numpy as np
from gymnasium.envs.mujoco import MujocoEnv
from metaworld.sawyer_xyz_env import SawyerXYZEnv

from lerobot_mtdagger.envs.drawers.mjcf import PAD_OFFSET_Y, drawer_mjcf
from lerobot_mtdagger.envs.drawers.variants import (
    DRAWER_STATE_NAMES,
    MAX_EPISODE_STEPS,
    PULL_FRACTION,
    SUCCESS_FRACTION,
    TABLE_X_LIMIT,
    TABLE_Y_RANGE,
    DrawerVariant,
    Placement,
    placement_named,
)

# Name prefixes of the geoms recoloured per reset (``Placement.colour``): case, drawer, handle.
_COLOURED_PARTS = ("case", "drawer", "handle")


def _metaworld_assets() -> Path:
    import metaworld

    return Path(metaworld.__file__).parent / "assets"


class DrawerSceneEnv(SawyerXYZEnv):
    """MetaWorld's Sawyer arena with one drawer; its MJCF is compiled from a temporary folder."""

    max_path_length = MAX_EPISODE_STEPS

    def __init__(self, variant: DrawerVariant, placement: Placement | None = None) -> None:
        """Builds the model of ``variant``; resets place it by ``placement`` (default setting if None)."""
        self.placement = placement_named(None) if placement is None else placement
        self.variant = variant
        self._tmp = tempfile.TemporaryDirectory(prefix="mtdagger-drawer-")
        root = Path(self._tmp.name)
        assets = _metaworld_assets()
        for folder in ("scene", "objects", "textures"):
            os.symlink(assets / folder, root / folder)
        (root / "sawyer_xyz").mkdir()
        self._model_path = str(root / "sawyer_xyz" / f"{variant.name}.xml")
        Path(self._model_path).write_text(drawer_mjcf(variant, lift=self.placement.lift))
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
        self._random_reset_space = gym.spaces.Box(*self.placement.reset_bounds, dtype=np.float64)
        self.goal_space = gym.spaces.Box(np.full(3, -np.inf), np.full(3, np.inf), dtype=np.float64)
        self._joint_qpos = self.model.jnt_qposadr[self.model.joint("drawer_slide").id]
        self._pad_geoms = {self.model.geom(n).id for n in ("leftpad_geom", "rightpad_geom")}
        self._pad_geoms |= {self.model.geom(n).id for n in ("leftclaw_it", "rightclaw_it")}
        self._handle_geoms = {
            i for i in range(self.model.ngeom) if (self.model.geom(i).name or "").startswith("handle_")
        }
        self._progress = 0
        self._target_pos = np.zeros(3)
        self._coloured_geoms = self._geoms_by_part()

    @property
    def model_name(self) -> str:
        """Path of the generated MJCF (exists only while the model compiles)."""
        return self._model_path

    @property
    def sawyer_observation_space(self) -> gym.spaces.Box:
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
        """Distance of each world point (N, 3+) to the nearest box/capsule/cylinder of ``geoms``, (N,)."""
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
        yaw = math.radians(v.yaw + offset[2])
        lift = offset[3] if len(offset) > 3 else 0.0
        x, y = v.x + offset[0], v.y + offset[1]
        if self.placement.keep_on_table:
            x, y = self._on_the_table(x, y, yaw)
        self.model.body("drawer_case").pos = (x, y, v.elevation + lift)
        self.model.body("drawer_case").quat = (math.cos(yaw / 2), 0.0, 0.0, math.sin(yaw / 2))
        if len(offset) > 3:
            self._recolour(np.asarray(offset[4:13]).reshape(3, 3))
        self.data.qpos[self._joint_qpos] = 0.0
        self.data.qvel[self.model.jnt_dofadr[self.model.joint("drawer_slide").id]] = 0.0
        mujoco.mj_forward(self.model, self.data)
        self._reset_hand()
        self._progress = 0
        self._target_pos = self.goal_position()
        return self._get_obs()

    def _on_the_table(self, x: float, y: float, yaw: float) -> tuple[float, float]:
        """The case front's (x, y), moved the least that keeps the turned case on the table, off the wall."""
        corners = self.variant.case_corners_xy(x, y, yaw)
        x -= max(0.0, corners[:, 0].max() - TABLE_X_LIMIT) - max(0.0, -TABLE_X_LIMIT - corners[:, 0].min())
        y -= max(0.0, corners[:, 1].max() - TABLE_Y_RANGE[1]) - max(
            0.0, TABLE_Y_RANGE[0] - corners[:, 1].min()
        )
        return x, y

    def _geoms_by_part(self) -> dict[str, tuple[list[int], np.ndarray]]:
        """Geom ids of the case, the drawer (front and box) and the handle, with their model colours."""
        parts: dict[str, tuple[list[int], np.ndarray]] = {}
        names = [self.model.geom(i).name or "" for i in range(self.model.ngeom)]
        for prefix in _COLOURED_PARTS:
            ids = [i for i, name in enumerate(names) if name.startswith(prefix + "_")]
            parts[prefix] = (ids, self.model.geom_rgba[ids].copy())
        return parts

    def _recolour(self, shifts: np.ndarray) -> None:
        """Shifts the RGB of the case, the drawer and the handle by one row of ``shifts`` each."""
        for prefix, shift in zip(_COLOURED_PARTS, shifts, strict=True):
            ids, base = self._coloured_geoms[prefix]
            colours = base.copy()
            colours[:, :3] = np.clip(base[:, :3] + shift, 0.0, 1.0)
            self.model.geom_rgba[ids] = colours

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
