"""Pictures of drawers for the docs (``render_drawer_picture``), drawn with MuJoCo's renderer."""

from __future__ import annotations

import mujoco
import numpy as np

from lerobot_mtdagger.envs.drawers.scene import DrawerSceneEnv
from lerobot_mtdagger.envs.drawers.variants import DrawerVariant


def render_drawer_picture(
    variant: DrawerVariant, height: int = 240, width: int = 320, opening_fraction: float = 0.5
) -> np.ndarray:
    """A drawer from the robot's side, (H, W, 3) uint8 (``ValueError``: opening_fraction not in [0, 1])."""
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
