"""The task-suite interface shared by the MetaWorld, drawer and toy suites.

A suite is a fixed, ordered list of tasks (task index i is ``task_names[i]`` everywhere). Its envs
emit dicts keyed by LeRobot feature names (``observation.state``, ``observation.image``,
``observation.pointcloud``) and put ``success`` and ``privileged_state`` (what the expert acts on) in
``info``; ``expert_family`` keys its experts in ``lerobot_mtdagger.experts``.
"""

from __future__ import annotations

import abc
import dataclasses
import functools
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from lerobot_mtdagger.utils.errors import UserError

OBS_MODES: tuple[str, ...] = ("state", "rgb", "pointcloud")

STATE_KEY = "observation.state"
IMAGE_KEY = "observation.image"
POINTCLOUD_KEY = "observation.pointcloud"


@dataclass(frozen=True)
class CropBox:
    """Axis-aligned box in world coordinates (metres) that keeps the workspace; corners are (x, y, z)."""

    low: tuple[float, float, float]
    high: tuple[float, float, float]

    def __post_init__(self) -> None:
        if len(self.low) != 3 or len(self.high) != 3:
            raise ValueError(
                f"CropBox corners need 3 coordinates each, got low={self.low}, high={self.high}."
            )
        if any(lo >= hi for lo, hi in zip(self.low, self.high, strict=True)):
            raise ValueError(f"CropBox low={self.low} must be below high={self.high} on every axis.")

    def contains(self, points: np.ndarray) -> np.ndarray:
        """Boolean mask of the rows of ``points`` (..., 3) inside the box."""
        return self.contains_planes(np.moveaxis(points, -1, 0))

    def contains_planes(self, planes: np.ndarray) -> np.ndarray:
        """Boolean mask (...) of the points given as coordinate planes ``planes`` (3, ...) inside the box.

        Several times faster than comparing (N, 3) rows for a depth camera's back-projected images.
        """
        inside = (planes[0] >= self.low[0]) & (planes[0] <= self.high[0])
        for axis in (1, 2):
            inside &= planes[axis] >= self.low[axis]
            inside &= planes[axis] <= self.high[axis]
        return inside

    @property
    def center(self) -> np.ndarray:
        """The box centre, shape (3,)."""
        return (np.asarray(self.low) + np.asarray(self.high)) / 2.0


@dataclass(frozen=True)
class ObservationConfig:
    """What a suite's envs show the policy.

    Attributes:
        obs_mode: ``state``, ``rgb`` or ``pointcloud``.
        image_size: Side of the square RGB image in ``rgb`` mode, pixels.
        camera: Camera of the RGB image.
        num_points: Points per cloud in ``pointcloud`` mode.
        pointcloud_cameras: Depth cameras fused into the cloud (None: the suite's default).
        depth_size: Side of the square depth images behind the cloud, pixels.
        pointcloud_color: Append per-point RGB in [0, 1] (cloud shape (num_points, 6)).
        crop: Workspace box of the cloud (None: the suite's default).
        include_goal: In ``rgb`` and ``pointcloud`` modes, append the goal position to the state.
        mesh_detail: Share of each large mesh's faces the observation renderer keeps (1: the exact
            model; ``rendering.simplified_model``).
    """

    obs_mode: str = "state"
    image_size: int = 84
    camera: str | None = None
    num_points: int = 1024
    pointcloud_cameras: tuple[str, ...] | None = None
    depth_size: int = 84
    pointcloud_color: bool = False
    crop: CropBox | None = None
    include_goal: bool = True
    mesh_detail: float = 1.0

    def __post_init__(self) -> None:
        if self.obs_mode not in OBS_MODES:
            raise ValueError(f"Unknown obs_mode {self.obs_mode!r}; choose one of {list(OBS_MODES)}.")
        if self.image_size <= 0:
            raise ValueError(f"image_size must be > 0, got {self.image_size}.")
        if self.depth_size <= 0:
            raise ValueError(f"depth_size must be > 0, got {self.depth_size}.")
        if self.num_points <= 0:
            raise ValueError(f"num_points must be > 0, got {self.num_points}.")
        if not 0.0 < self.mesh_detail <= 1.0:
            raise ValueError(f"mesh_detail must be in (0, 1], got {self.mesh_detail}.")
        if self.pointcloud_cameras is not None and len(self.pointcloud_cameras) == 0:
            raise ValueError("pointcloud_cameras is empty: name at least one camera or pass None.")


class TaskSuite(abc.ABC):
    """A fixed, ordered set of tasks with envs, experts and LeRobot features."""

    name: str
    expert_family: str
    """Key of the suite's experts in the expert registry (``lerobot_mtdagger.experts``)."""

    def __init__(self, task_names: Sequence[str], observation: ObservationConfig) -> None:
        """Stores the task order and observation settings (``ValueError`` on an empty or duplicated list)."""
        task_names = list(task_names)
        if not task_names:
            raise ValueError(f"Suite {self.name!r} needs at least one task.")
        duplicates = sorted({t for t in task_names if task_names.count(t) > 1})
        if duplicates:
            raise ValueError(f"Task names must be unique; repeated: {duplicates}.")
        self.task_names = task_names
        self.observation = observation
        self.expert_overrides: dict[str, Any] = {}
        # How far the experts are from perfect (``experts.noise.ExpertNoise``; None: as they are)
        self.expert_noise: Any = None
        # Unseen tasks the suite builds envs and experts for (evaluation only; no task index).
        self.heldout_task_names: list[str] = []

    reports_progress: bool = False
    """Whether the envs' ``info`` carries ``progress`` (the drawers' 0-3 score)."""

    @property
    def obs_mode(self) -> str:
        """The observation mode of every env of the suite."""
        return self.observation.obs_mode

    def heldout_suite(self) -> TaskSuite | None:
        """A suite whose tasks are this suite's held-out tasks (same observations), or None without any."""
        return None

    def nearest_training_task(self, task_name: str, training_tasks: Sequence[str]) -> str:
        """The training task most like the unseen ``task_name`` (a ``UserError`` here; drawers override)."""
        raise UserError(
            f"Suite {self.name!r} has no rule for the training task most like {task_name!r}: evaluate "
            "it with --unseen_rule=shared (a policy trained with --policy.task_dropout > 0)."
        )

    def task_index(self, task_name: str) -> int:
        """Index of ``task_name`` in ``task_names``; a ``ValueError`` if it is not in the suite."""
        if task_name not in self.task_names:
            raise ValueError(
                f"Task {task_name!r} is not in suite {self.name!r}; its tasks: {self.task_names}."
            )
        return self.task_names.index(task_name)

    @abc.abstractmethod
    def make_env(self, task_name: str, seed: int | None = None) -> gym.Env:
        """Builds the env of one task; ``seed`` seeds its first reset."""

    def check_buildable(self, task_name: str) -> None:
        """Checks that the suite builds ``task_name`` (a task or a held-out one); ``ValueError`` otherwise."""
        if task_name not in self.task_names and task_name not in self.heldout_task_names:
            raise ValueError(
                f"Task {task_name!r} is neither a task of suite {self.name!r} {self.task_names} nor held out "
                f"{self.heldout_task_names}."
            )

    def with_experts(self, experts: dict[str, Any]) -> TaskSuite:
        """A copy of the suite whose ``make_expert`` gives these experts for some tasks (e.g. RL policies).

        Raises:
            ValueError: On a task not in the suite.
            TypeError: On an object without the ``Expert`` protocol's ``reset()`` and ``act(state)``.
        """
        for task_name, expert in experts.items():
            self.task_index(task_name)
            if not (callable(getattr(expert, "reset", None)) and callable(getattr(expert, "act", None))):
                raise TypeError(
                    f"The expert for {task_name!r} is a {type(expert).__name__} without reset() and "
                    "act(privileged_state); wrap a function with CallableExpert or a LeRobot policy with "
                    "LeRobotPolicyExpert."
                )
        clone = self.with_observation()
        clone.expert_overrides = {**self.expert_overrides, **experts}
        return clone

    @property
    @abc.abstractmethod
    def features(self) -> dict[str, dict[str, Any]]:
        """LeRobot feature dict (dtype, shape, names) of the observations plus ``action``."""

    @property
    @abc.abstractmethod
    def action_dim(self) -> int:
        """Size of the action vector."""

    def with_expert_noise(self, noise: Any) -> TaskSuite:
        """A copy of the suite whose experts act with ``noise`` (``ExpertNoise``; None or scale 0: none)."""
        clone = self.with_observation()
        clone.expert_noise = noise if noise is not None and noise.active else None
        return clone

    def with_observation(self, **changes: Any) -> TaskSuite:
        """A copy of the suite with some observation settings changed."""
        clone = self.__class__.__new__(self.__class__)
        clone.__dict__.update(self.__dict__)
        clone.observation = dataclasses.replace(self.observation, **changes)
        return clone

    def make_vector_env(
        self, task_names: Sequence[str], seeds: Sequence[int], asynchronous: bool = True
    ) -> gym.vector.VectorEnv:
        """Several tasks' envs stepped together (one process each when ``asynchronous``).

        Autoreset is disabled: reset finished sub-envs with ``envs.reset(options={"reset_mask": done})``.
        ``seeds`` seed each sub-env's first reset.

        Raises:
            ValueError: On mismatched lengths or an unknown task.
        """
        if len(task_names) != len(seeds):
            raise ValueError(
                f"Got {len(task_names)} task names but {len(seeds)} seeds; give one seed per env."
            )
        for task_name in task_names:
            self.task_index(task_name)
        env_fns = [
            functools.partial(self.make_env, t, int(s)) for t, s in zip(task_names, seeds, strict=True)
        ]
        mode = gym.vector.AutoresetMode.DISABLED
        if asynchronous:
            return gym.vector.AsyncVectorEnv(env_fns, autoreset_mode=mode)
        return gym.vector.SyncVectorEnv(env_fns, autoreset_mode=mode)

    def __repr__(self) -> str:
        name = self.__class__.__name__
        return f"{name}(name={self.name!r}, tasks={len(self.task_names)}, obs_mode={self.obs_mode!r})"


def observation_features(
    config: ObservationConfig, state_names: Sequence[str], action_names: Sequence[str]
) -> dict[str, dict[str, Any]]:
    """LeRobot features of what a suite emits in the mode of ``config``, plus ``action``."""
    features = {STATE_KEY: state_feature(state_names)}
    if config.obs_mode == "rgb":
        features[IMAGE_KEY] = image_feature(config.image_size)
    elif config.obs_mode == "pointcloud":
        features[POINTCLOUD_KEY] = pointcloud_feature(config.num_points, 6 if config.pointcloud_color else 3)
    features["action"] = state_feature(action_names)
    return features


def state_feature(names: Sequence[str]) -> dict[str, Any]:
    """LeRobot feature of a float32 state vector."""
    return {"dtype": "float32", "shape": (len(names),), "names": list(names)}


def image_feature(size: int) -> dict[str, Any]:
    """LeRobot feature of a square RGB image stored as PNG frames (no video decoding needed)."""
    return {"dtype": "image", "shape": (size, size, 3), "names": ["height", "width", "channels"]}


def pointcloud_feature(num_points: int, channels: int) -> dict[str, Any]:
    """LeRobot feature of a point cloud: channels are x, y, z (world frame, metres) then r, g, b."""
    return {"dtype": "float32", "shape": (num_points, channels), "names": ["points", "channels"]}
