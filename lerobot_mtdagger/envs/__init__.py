"""Task suites with state, RGB and point-cloud observations.

``make_suite(name, tasks=None, obs_mode="state", ...)`` builds a suite:

==================  =====================================================================
name                tasks
==================  =====================================================================
metaworld-mt10      MetaWorld's MT10 list (v3 envs)
metaworld-mt25      MetaWorld's MT25 list
metaworld-mt50      MetaWorld's MT50 list (all v3 tasks)
metaworld           any explicit ``tasks=[...]`` list of v3 task names
drawers             the 11 procedurally generated training drawers (``envs/drawers/``);
                    ``suite.heldout_task_names`` are unseen drawers the suite also builds
toy                 a point mass pushed to task-specific goals (``envs/toy.py``): no MuJoCo,
                    state only, for fast tests
==================  =====================================================================

``suite_from_config(config)`` builds the suite a ``SuiteConfig`` names (``run``, ``eval``, ``shift``
and the LeRobot env plugin each hold one: ``envs/config.py``).

``tasks=[...]`` with a named list selects a subset in the given order. Rendering uses MuJoCo's EGL
backend unless ``MUJOCO_GL`` is already set (``osmesa`` is the fallback without EGL).
"""

from __future__ import annotations

import os

os.environ.setdefault("MUJOCO_GL", "egl")
os.environ.setdefault("PYOPENGL_PLATFORM", os.environ["MUJOCO_GL"])

from collections.abc import Sequence  # noqa: E402
from typing import Any  # noqa: E402

from lerobot_mtdagger.envs.base import (  # noqa: E402
    IMAGE_KEY,
    OBS_MODES,
    POINTCLOUD_KEY,
    STATE_KEY,
    CropBox,
    ObservationConfig,
    TaskSuite,
)
from lerobot_mtdagger.envs.config import (  # noqa: E402
    DEFAULT_IMAGE_SIZE,
    DEFAULT_NUM_POINTS,
    SuiteConfig,
)
from lerobot_mtdagger.utils.errors import UserError  # noqa: E402

SUITE_NAMES: tuple[str, ...] = (
    "metaworld-mt10",
    "metaworld-mt25",
    "metaworld-mt50",
    "metaworld",
    "drawers",
    "toy",
)

__all__ = [
    "IMAGE_KEY",
    "OBS_MODES",
    "POINTCLOUD_KEY",
    "STATE_KEY",
    "SUITE_NAMES",
    "CropBox",
    "ObservationConfig",
    "TaskSuite",
    "SuiteConfig",
    "make_suite",
    "suite_from_config",
]


def make_suite(
    name: str,
    *,
    tasks: Sequence[str] | None = None,
    obs_mode: str = "state",
    image_size: int = 84,
    camera: str | None = None,
    num_points: int = 1024,
    pointcloud_cameras: Sequence[str] | None = None,
    depth_size: int = 84,
    pointcloud_color: bool = False,
    crop: CropBox | None = None,
    include_goal: bool = True,
    max_episode_steps: int | None = None,
    placement: str | None = None,
    mesh_detail: float = 1.0,
) -> TaskSuite:
    """Builds a task suite.

    Args:
        name: One of ``SUITE_NAMES``.
        tasks: Task subset (any order); required for ``metaworld``, optional for the named lists.
        obs_mode: ``state``, ``rgb`` or ``pointcloud``.
        image_size: RGB image side in pixels.
        camera: RGB camera name (suite default when None).
        num_points: Points per cloud.
        pointcloud_cameras: Depth cameras of the cloud (suite default when None).
        depth_size: Depth image side in pixels.
        pointcloud_color: Add per-point RGB.
        crop: Crop box of the cloud (suite default when None).
        include_goal: Append the goal position to the proprioceptive state in rgb/pointcloud modes.
        max_episode_steps: Truncation length (the task's max path length when None).
        placement: ``drawers`` only: how resets move and recolour the drawers (``kitchen``, the
            default, or ``narrow``; see ``lerobot_mtdagger.envs.drawers.PLACEMENTS``).
        mesh_detail: Share of the faces of each large mesh the observation renderer keeps (1: all).

    Returns:
        The suite.

    Raises:
        ValueError: On an unknown suite, task or observation setting.
    """
    observation = ObservationConfig(
        obs_mode=obs_mode,
        image_size=image_size,
        camera=camera,
        num_points=num_points,
        pointcloud_cameras=None if pointcloud_cameras is None else tuple(pointcloud_cameras),
        depth_size=depth_size,
        mesh_detail=mesh_detail,
        pointcloud_color=pointcloud_color,
        crop=crop,
        include_goal=include_goal,
    )
    if name not in SUITE_NAMES:
        raise UserError(f"Unknown suite {name!r}; available suites: {list(SUITE_NAMES)}.")
    if name == "drawers":
        from lerobot_mtdagger.envs.drawers import DRAWER_TASKS, PLACEMENTS, DrawerSuite

        if placement is not None and placement not in PLACEMENTS:
            raise UserError(f"Unknown drawer placement {placement!r}; choose one of {sorted(PLACEMENTS)}.")
        task_names = list(tasks) if tasks else list(DRAWER_TASKS)
        return DrawerSuite(task_names, observation, max_episode_steps=max_episode_steps, placement=placement)
    if placement is not None:
        raise UserError(f"placement={placement!r} applies to the drawers suite only; drop it for {name!r}.")
    if name == "toy":
        from lerobot_mtdagger.envs.toy import TOY_TASKS, ToySuite

        return ToySuite(list(tasks) if tasks else list(TOY_TASKS), observation, max_episode_steps)
    from lerobot_mtdagger.envs.metaworld import MT10_TASKS, MT25_TASKS, MT50_TASKS, MetaWorldSuite

    named_lists = {"metaworld-mt10": MT10_TASKS, "metaworld-mt25": MT25_TASKS, "metaworld-mt50": MT50_TASKS}
    if name == "metaworld":
        if not tasks:
            raise UserError("Suite 'metaworld' needs an explicit tasks=[...] list of v3 task names.")
        task_names = list(tasks)
    else:
        available = named_lists[name]
        task_names = list(tasks) if tasks else list(available)
        outside = [t for t in task_names if t not in available]
        if outside:
            raise UserError(f"Task(s) {outside} are not in {name}; its tasks: {list(available)}.")
    return MetaWorldSuite(task_names, observation, max_episode_steps=max_episode_steps, name=name)


def suite_from_config(config: SuiteConfig, **overrides: Any) -> TaskSuite:
    """The suite a ``SuiteConfig`` names (unset observation options at their defaults).

    Args:
        config: The command's suite options.
        **overrides: ``make_suite`` keyword arguments that replace the config's.

    Raises:
        UserError: On an unknown suite, task or observation setting (one line, naming the option).
    """
    if config.name is None:
        raise UserError("No suite given: pass --suite.name (e.g. --suite.name=metaworld-mt10).")
    config.check()
    options: dict[str, Any] = {
        "tasks": list(config.tasks) if config.tasks else None,
        "obs_mode": config.obs_mode or "state",
        "image_size": config.image_size or DEFAULT_IMAGE_SIZE,
        "num_points": config.num_points or DEFAULT_NUM_POINTS,
        "max_episode_steps": config.episode_length,
        "placement": config.placement,
        "mesh_detail": config.mesh_detail,
    }
    try:
        return make_suite(config.name, **(options | overrides))
    except UserError:
        raise
    except ValueError as error:  # a bad suite, task or observation option: the user's to fix
        raise UserError(str(error)) from None
