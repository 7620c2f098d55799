"""Task suites with state, RGB and point-cloud observations.

``make_suite(name, tasks=None, observation=ObservationConfig(...))`` builds a registered suite:
``metaworld-mt10``/``-mt25``/``-mt50`` (MetaWorld's lists), ``metaworld`` (any ``tasks=[...]`` of v3
names), ``drawers`` (11 generated drawers and unseen ones, ``envs/drawers/``) and ``toy`` (a point
mass, no MuJoCo, for fast tests). ``register_suite`` adds one (``docs/suites.md``); a ``SuiteConfig``
(``envs/config.py``) names one for ``suite_from_config``. Rendering uses MuJoCo's EGL backend unless
``MUJOCO_GL`` is set (``osmesa`` without EGL).
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
from lerobot_mtdagger.envs.registry import (  # noqa: E402
    BUILT_IN_SUITES,
    SuiteFactory,
    SuiteOptions,
    build_suite,
    import_suite_module,
    register_suite,
    suite_names,
)
from lerobot_mtdagger.utils.errors import UserError  # noqa: E402

SUITE_NAMES: tuple[str, ...] = tuple(BUILT_IN_SUITES)
"""The package's own suites (``suite_names()``: every registered one)."""

__all__ = [
    "IMAGE_KEY",
    "OBS_MODES",
    "POINTCLOUD_KEY",
    "STATE_KEY",
    "SUITE_NAMES",
    "CropBox",
    "ObservationConfig",
    "SuiteConfig",
    "SuiteFactory",
    "SuiteOptions",
    "TaskSuite",
    "make_suite",
    "register_suite",
    "suite_from_config",
    "suite_names",
]


def make_suite(
    name: str,
    *,
    tasks: Sequence[str] | None = None,
    observation: ObservationConfig | None = None,
    max_episode_steps: int | None = None,
    placement: str | None = None,
) -> TaskSuite:
    """Builds a registered task suite.

    Args:
        name: A registered suite name (``suite_names()``).
        tasks: Task subset in the given order; required for ``metaworld``, optional for the named lists.
        observation: What the envs show the policy (None: state).
        max_episode_steps: Truncation length (None: each task's own horizon).
        placement: ``drawers`` only: how resets move and recolour the drawers (``PLACEMENTS``).

    Raises:
        ValueError: On an unknown suite, task or observation setting.
    """
    options = SuiteOptions(
        name=name,
        tasks=tuple(tasks or ()),
        observation=observation or ObservationConfig(),
        max_episode_steps=max_episode_steps,
        placement=placement,
    )
    return build_suite(options)


def suite_from_config(config: SuiteConfig, **overrides: Any) -> TaskSuite:
    """The suite a ``SuiteConfig`` names, after importing its ``module`` (``UserError``: one line)."""
    if config.name is None:
        raise UserError("No suite given: pass --suite.name (e.g. --suite.name=metaworld-mt10).")
    config.check()
    if config.module is not None:
        import_suite_module(config.module)
    try:
        options: dict[str, Any] = {
            "tasks": list(config.tasks) if config.tasks else None,
            "observation": ObservationConfig(
                obs_mode=config.obs_mode or "state",
                image_size=config.image_size or DEFAULT_IMAGE_SIZE,
                num_points=config.num_points or DEFAULT_NUM_POINTS,
                mesh_detail=config.mesh_detail,
            ),
            "max_episode_steps": config.episode_length,
            "placement": config.placement,
        }
        return make_suite(config.name, **(options | overrides))
    except UserError:
        raise
    except ValueError as error:  # a bad suite, task or observation option: the user's to fix
        raise UserError(str(error)) from None
