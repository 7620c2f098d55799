"""MetaWorld 3.1 (v3 environments) as multitask suites with state, RGB and point-cloud observations.

``state`` is MetaWorld's 39-d goal-visible vector (the expert's privileged state); ``rgb`` and
``pointcloud`` add the image or the cropped world-frame cloud of the ``corner``/``corner2`` depth
cameras to hand xyz + gripper opening (+ goal with ``include_goal``). Seeded resets reproduce the
initial positions; an episode succeeds if ``info["success"]`` was true at any step.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

import gymnasium as gym
import numpy as np
from metaworld.env_dict import ALL_V3_ENVIRONMENTS, MT10_V3, MT25_V3, MT50_V3

from lerobot_mtdagger.envs.base import (
    IMAGE_KEY,
    POINTCLOUD_KEY,
    STATE_KEY,
    ObservationConfig,
    TaskSuite,
    observation_features,
)
from lerobot_mtdagger.envs.registry import SuiteOptions
from lerobot_mtdagger.envs.rendering import (
    CropBox,
    PointCloudCamera,
    SceneRenderer,
    camera_rays,
    simplified_model,
)
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

MT10_TASKS: tuple[str, ...] = tuple(MT10_V3)
MT25_TASKS: tuple[str, ...] = tuple(MT25_V3)
MT50_TASKS: tuple[str, ...] = tuple(MT50_V3)
ALL_TASKS: tuple[str, ...] = tuple(ALL_V3_ENVIRONMENTS)
NAMED_TASK_LISTS: dict[str, tuple[str, ...]] = {
    "metaworld-mt10": MT10_TASKS,
    "metaworld-mt25": MT25_TASKS,
    "metaworld-mt50": MT50_TASKS,
}
"""The suites named after one of MetaWorld's lists, and their tasks."""

METAWORLD_CROP = CropBox(low=(-0.6, 0.2, 0.01), high=(0.6, 1.1, 0.7))
DEFAULT_CAMERA = "corner"
# MetaWorld's corner cameras are mounted upside down (their image "up" is the world's down); their
# RGB observations are rotated by 180 degrees so the table is at the bottom of the image.
UPSIDE_DOWN_CAMERAS = frozenset({"corner", "corner2", "corner3", "corner4"})
DEFAULT_POINTCLOUD_CAMERAS: tuple[str, ...] = ("corner", "corner2")
ACTION_DIM = 4

_OBJECT_NAMES = [f"obj{k}_{axis}" for k in (0, 1) for axis in ("x", "y", "z", "qw", "qx", "qy", "qz")]
_FRAME_NAMES = ["hand_x", "hand_y", "hand_z", "gripper", *_OBJECT_NAMES]
STATE_NAMES: list[str] = _FRAME_NAMES + [f"prev_{n}" for n in _FRAME_NAMES] + ["goal_x", "goal_y", "goal_z"]
PROPRIO_NAMES: list[str] = ["hand_x", "hand_y", "hand_z", "gripper"]
GOAL_NAMES: list[str] = ["goal_x", "goal_y", "goal_z"]
ACTION_NAMES: list[str] = ["dx", "dy", "dz", "grip"]


def observation_state_names(config: ObservationConfig) -> list[str]:
    """Names of the entries of ``observation.state`` in the mode of ``config``."""
    if config.obs_mode == "state":
        return STATE_NAMES
    return PROPRIO_NAMES + (GOAL_NAMES if config.include_goal else [])


def _make_raw_env(task_name: str) -> Any:
    """A v3 env with the goal visible and seedable random resets (``seeded_rand_vec``, no frozen goal)."""
    env = ALL_V3_ENVIRONMENTS[task_name]()
    env._partially_observable = False
    del env.sawyer_observation_space  # cached property computed for the hidden goal
    env._freeze_rand_vec = False
    env.seeded_rand_vec = True
    env._set_task_called = True
    return env


class MetaWorldTaskEnv(gym.Env):
    """One MetaWorld v3 task with LeRobot-keyed dict observations.

    Other scenes of the Sawyer arena (the drawers) override ``_build_raw_env``, ``state_names``,
    ``_proprio_state``, ``_step_info`` and the camera and crop defaults.
    """

    metadata = {"render_modes": ["rgb_array"], "render_fps": 80}
    default_camera: str = DEFAULT_CAMERA
    default_pointcloud_cameras: tuple[str, ...] = DEFAULT_POINTCLOUD_CAMERAS
    default_crop: CropBox = METAWORLD_CROP

    def __init__(
        self,
        task_name: str,
        observation: ObservationConfig,
        seed: int | None = None,
        max_episode_steps: int | None = None,
    ) -> None:
        """Builds the env of a v3 task such as ``reach-v3`` (about 0.2 s).

        ``seed`` seeds the first reset; ``max_episode_steps`` None: MetaWorld's max path length (500).
        """
        self.task_name = task_name
        self.observation_config = observation
        self._env = self._build_raw_env()
        self.max_episode_steps = int(max_episode_steps or self._env.max_path_length)
        limit = self._env.max_path_length
        if not 0 < self.max_episode_steps <= limit:
            raise ValueError(f"max_episode_steps must be in [1, {limit}], got {self.max_episode_steps}.")
        self._pending_seed = seed
        self._elapsed = 0
        self._needs_reset = True
        self._point_rng = np.random.default_rng(seed)
        self._renderer: SceneRenderer | None = None
        self._cloud: PointCloudCamera | None = None
        self._setup_rendering()
        self.action_space = gym.spaces.Box(-1.0, 1.0, (ACTION_DIM,), dtype=np.float32)
        self.observation_space = self._make_observation_space()

    # ---------------------------------------------------------------------------------------------
    # Hooks of subclasses
    # ---------------------------------------------------------------------------------------------

    def _build_raw_env(self) -> Any:
        """The underlying MetaWorld (``SawyerXYZEnv``) env of ``self.task_name``."""
        return _make_raw_env(self.task_name)

    def state_names(self) -> list[str]:
        """Names of the entries of ``observation.state``."""
        return observation_state_names(self.observation_config)

    def _proprio_state(self, raw: np.ndarray) -> np.ndarray:
        """``observation.state`` in the rgb and point-cloud modes, from the raw MetaWorld state."""
        if self.observation_config.include_goal:
            return np.concatenate([raw[:4], raw[36:39]])
        return raw[:4]

    def _step_info(self, raw: np.ndarray, raw_info: dict[str, Any]) -> dict[str, Any]:
        """The info dict of a step (and, with an empty ``raw_info``, of a reset)."""
        success = bool(raw_info.get("success", False))
        return {
            "success": success,
            "is_success": success,
            "privileged_state": raw.copy(),
            "task": self.task_name,
        }

    # ---------------------------------------------------------------------------------------------
    # Spaces and rendering
    # ---------------------------------------------------------------------------------------------

    def _setup_rendering(self) -> None:
        config = self.observation_config
        model = self._env.model
        if config.obs_mode != "state" and config.mesh_detail < 1.0:
            model = simplified_model(model, config.mesh_detail)
        if config.obs_mode == "rgb":
            self._renderer = SceneRenderer(model, config.image_size, config.image_size)
            self._camera = config.camera or self.default_camera
            camera_rays(model, self._camera, 1, 1)  # fail now, not at the first frame, on a misspelt camera
        elif config.obs_mode == "pointcloud":
            self._renderer = SceneRenderer(model, config.depth_size, config.depth_size)
            self._cloud = PointCloudCamera(
                self._renderer,
                config.pointcloud_cameras or self.default_pointcloud_cameras,
                config.crop or self.default_crop,
                config.num_points,
                with_color=config.pointcloud_color,
            )

    def _make_observation_space(self) -> gym.spaces.Dict:
        config = self.observation_config
        spaces: dict[str, gym.Space] = {
            STATE_KEY: gym.spaces.Box(-np.inf, np.inf, (len(self.state_names()),), dtype=np.float32)
        }
        if config.obs_mode == "rgb":
            spaces[IMAGE_KEY] = gym.spaces.Box(
                0, 255, (config.image_size, config.image_size, 3), dtype=np.uint8
            )
        elif config.obs_mode == "pointcloud":
            assert self._cloud is not None
            shape = (config.num_points, self._cloud.channels)
            spaces[POINTCLOUD_KEY] = gym.spaces.Box(-np.inf, np.inf, shape, dtype=np.float32)
        return gym.spaces.Dict(spaces)

    def _observation(self, raw: np.ndarray) -> dict[str, np.ndarray]:
        config = self.observation_config
        if config.obs_mode == "state":
            return {STATE_KEY: raw.astype(np.float32)}
        observation = {STATE_KEY: self._proprio_state(raw).astype(np.float32)}
        if config.obs_mode == "rgb":
            assert self._renderer is not None
            observation[IMAGE_KEY] = self._rgb(self._camera)
        else:
            assert self._cloud is not None
            observation[POINTCLOUD_KEY] = self._cloud.capture(self._env.data, self._point_rng)
        return observation

    def _rgb(self, camera: str) -> np.ndarray:
        assert self._renderer is not None
        image = self._renderer.rgb(self._env.data, camera)
        if camera in UPSIDE_DOWN_CAMERAS:
            image = np.ascontiguousarray(image[::-1, ::-1])
        return image

    def render(self) -> np.ndarray:
        """An RGB frame of the observation camera (for videos), (H, W, 3) uint8."""
        if self._renderer is None:
            size = self.observation_config.image_size
            self._renderer = SceneRenderer(self._env.model, size, size)
        return self._rgb(self.observation_config.camera or self.default_camera)

    # ---------------------------------------------------------------------------------------------
    # Gymnasium API
    # ---------------------------------------------------------------------------------------------

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        """Starts an episode; the same seed gives the same initial object and goal positions."""
        if seed is None and self._pending_seed is not None:
            seed = self._pending_seed
        self._pending_seed = None
        super().reset(seed=seed)
        if seed is not None:
            self._env.seed(int(seed))
            self._point_rng = np.random.default_rng(int(seed))
        raw, _ = self._env.reset()
        self._elapsed = 0
        self._needs_reset = False
        return self._observation(raw), self._step_info(raw, {})

    def step(self, action: np.ndarray) -> tuple[dict[str, np.ndarray], float, bool, bool, dict[str, Any]]:
        """Applies one action (clipped to [-1, 1]).

        Raises:
            RuntimeError: If the episode ended and ``reset`` was not called.
            ValueError: If the action does not have 4 finite entries.
        """
        if self._needs_reset:
            raise RuntimeError(
                f"{self.task_name}: the episode is over (or never started); call reset() first."
            )
        action = np.asarray(action, dtype=np.float32).reshape(-1)
        if action.shape != (ACTION_DIM,) or not np.all(np.isfinite(action)):
            raise ValueError(f"{self.task_name}: actions are 4 finite numbers in [-1, 1], got {action}.")
        raw, reward, _, _, raw_info = self._env.step(np.clip(action, -1.0, 1.0))
        self._elapsed += 1
        truncated = self._elapsed >= self.max_episode_steps
        self._needs_reset = truncated
        return self._observation(raw), float(reward), False, truncated, self._step_info(raw, raw_info)

    def close(self) -> None:
        """Frees the renderer and the MuJoCo model."""
        if self._renderer is not None:
            self._renderer.close()
            self._renderer = None
        self._env.close()


class MetaWorldSuite(TaskSuite):
    """MetaWorld v3 tasks: MT10, MT25, MT50 or any explicit list."""

    name = "metaworld"
    expert_family = "metaworld"

    def __init__(
        self,
        task_names: Sequence[str],
        observation: ObservationConfig,
        max_episode_steps: int | None = None,
        name: str = "metaworld",
    ) -> None:
        """Checks the task names against MetaWorld's v3 environments (a ``ValueError`` on an unknown one)."""
        unknown = [t for t in task_names if t not in ALL_V3_ENVIRONMENTS]
        if unknown:
            raise UserError(f"Unknown MetaWorld v3 task(s) {unknown}; known tasks: {list(ALL_TASKS)}.")
        self.name = name
        super().__init__(task_names, observation)
        self.max_episode_steps = max_episode_steps

    @property
    def action_dim(self) -> int:
        """MetaWorld's 4-d action: end-effector displacement xyz and gripper effort."""
        return ACTION_DIM

    def make_env(self, task_name: str, seed: int | None = None) -> MetaWorldTaskEnv:
        """Builds the env of ``task_name``."""
        self.task_index(task_name)
        return MetaWorldTaskEnv(
            task_name, self.observation, seed=seed, max_episode_steps=self.max_episode_steps
        )

    @property
    def features(self) -> dict[str, dict[str, Any]]:
        """LeRobot features of the observations of the current mode, plus ``action``."""
        return observation_features(self.observation, observation_state_names(self.observation), ACTION_NAMES)


def build_metaworld_suite(options: SuiteOptions) -> MetaWorldSuite:
    """The factory of the MetaWorld suites: ``metaworld-mt10/25/50`` (a subset of a list), ``metaworld``.

    Raises:
        UserError: On a placement, a task outside the named list, or no task for ``metaworld``.
    """
    options.refuse_placement()
    available = NAMED_TASK_LISTS.get(options.name)
    if available is None:
        if not options.tasks:
            raise UserError(f"Suite {options.name!r} needs an explicit tasks=[...] list of v3 task names.")
        task_names = list(options.tasks)
    else:
        task_names = options.task_list(available)
        outside = [t for t in task_names if t not in available]
        if outside:
            raise UserError(f"Task(s) {outside} are not in {options.name}; its tasks: {list(available)}.")
    return MetaWorldSuite(
        task_names, options.observation, max_episode_steps=options.max_episode_steps, name=options.name
    )
