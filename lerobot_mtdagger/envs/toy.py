"""A toy multitask suite without MuJoCo: a point mass pushed to a task-specific goal under wind.

For tests: the whole DAgger chain runs on it in seconds. The policy sees only the position, so it
must use the task; the expert sees goal and wind too and is optimal; a learner that outputs zeros
drifts with the wind and never succeeds.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import gymnasium as gym
import numpy as np

from lerobot_mtdagger.envs.base import STATE_KEY, ObservationConfig, TaskSuite, state_feature
from lerobot_mtdagger.envs.registry import SuiteOptions

STEP_SIZE = 0.05
SUCCESS_RADIUS = 0.05
MAX_EPISODE_STEPS = 40
START_BOX = 0.3  # starts are uniform in [-START_BOX, START_BOX]^2
STATE_NAMES = ["x", "y"]
ACTION_NAMES = ["push_x", "push_y"]


@dataclass(frozen=True)
class ToyTask:
    """One toy task: where the goal is and how the wind blows (metres per step)."""

    name: str
    goal: tuple[float, float]
    wind: tuple[float, float] = (0.0, 0.0)


TOY_TASKS: dict[str, ToyTask] = {
    task.name: task
    for task in (
        ToyTask("toy-left", goal=(-0.6, 0.0)),
        ToyTask("toy-right", goal=(0.6, 0.0), wind=(0.0, 0.01)),
        ToyTask("toy-up-windy", goal=(0.0, 0.6), wind=(0.02, -0.01)),
    )
}
"""The default toy tasks, easy to hard (the wind grows)."""


class ToyEnv(gym.Env):
    """One toy task with the suite env interface (dict observations, privileged state in ``info``)."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 10}

    def __init__(self, task: ToyTask, seed: int | None = None, max_episode_steps: int | None = None) -> None:
        """Builds the env; ``seed`` seeds its first reset."""
        self.task = task
        self.max_episode_steps = max_episode_steps or MAX_EPISODE_STEPS
        self.observation_space = gym.spaces.Dict(
            {STATE_KEY: gym.spaces.Box(-np.inf, np.inf, shape=(2,), dtype=np.float32)}
        )
        self.action_space = gym.spaces.Box(-1.0, 1.0, shape=(2,), dtype=np.float32)
        self._goal = np.asarray(task.goal, dtype=np.float64)
        self._wind = np.asarray(task.wind, dtype=np.float64)
        self._position: np.ndarray = np.zeros(2)
        self._steps = 0
        self._first_seed = seed

    def _observe(self) -> tuple[dict[str, np.ndarray], dict[str, Any]]:
        observation = {STATE_KEY: self._position.astype(np.float32)}
        privileged = np.concatenate([self._position, self._goal, self._wind]).astype(np.float32)
        success = bool(np.linalg.norm(self._position - self._goal) < SUCCESS_RADIUS)
        return observation, {"privileged_state": privileged, "success": success}

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        """Draws a start position from the seeded generator."""
        if seed is None and self._first_seed is not None:
            seed, self._first_seed = self._first_seed, None
        super().reset(seed=seed)
        self._position = self.np_random.uniform(-START_BOX, START_BOX, size=2)
        self._steps = 0
        return self._observe()

    def step(self, action: np.ndarray) -> tuple[dict, float, bool, bool, dict]:
        """Moves the point; the reward is the negative distance to the goal."""
        action = np.asarray(action, dtype=np.float64).reshape(-1)
        if action.shape != (2,):
            raise ValueError(f"The toy env takes 2-d actions, got shape {action.shape}.")
        self._position = self._position + STEP_SIZE * np.clip(action, -1.0, 1.0) + self._wind
        self._steps += 1
        observation, info = self._observe()
        reward = -float(np.linalg.norm(self._position - self._goal))
        return observation, reward, False, self._steps >= self.max_episode_steps, info

    def render(self) -> np.ndarray:
        """A 32 x 32 picture: the goal in green, the point in red (world [-1, 1]^2, y up)."""
        image = np.full((32, 32, 3), 255, dtype=np.uint8)
        for xy, colour in ((self._goal, (0, 160, 0)), (self._position, (200, 0, 0))):
            col, row = np.clip(((np.asarray(xy) * [1, -1] + 1) * 16).astype(int), 0, 31)
            image[max(row - 1, 0) : row + 2, max(col - 1, 0) : col + 2] = colour
        return image


class ToySuite(TaskSuite):
    """The toy point-mass suite (state observations only)."""

    name = "toy"
    expert_family = "toy"

    def __init__(
        self,
        task_names: Sequence[str],
        observation: ObservationConfig,
        max_episode_steps: int | None = None,
        tasks: Sequence[ToyTask] = (),
    ) -> None:
        """Selects the tasks, of ``TOY_TASKS`` or ``tasks`` (``ValueError`` if unknown, or not ``state``)."""
        if observation.obs_mode != "state":
            raise ValueError(
                f"The toy suite has state observations only, got obs_mode={observation.obs_mode!r}."
            )
        self.tasks = {**TOY_TASKS, **{task.name: task for task in tasks}}
        unknown = [t for t in task_names if t not in self.tasks]
        if unknown:
            raise ValueError(f"Unknown toy task(s) {unknown}; known toy tasks: {sorted(self.tasks)}.")
        super().__init__(task_names, observation)
        self.max_episode_steps = max_episode_steps

    @property
    def action_dim(self) -> int:
        """The 2-d push."""
        return 2

    def make_env(self, task_name: str, seed: int | None = None) -> ToyEnv:
        """Builds the env of one task."""
        self.check_buildable(task_name)
        return ToyEnv(self.tasks[task_name], seed=seed, max_episode_steps=self.max_episode_steps)

    @property
    def features(self) -> dict[str, dict[str, Any]]:
        """``observation.state`` (x, y) and ``action`` (push x, y)."""
        return {STATE_KEY: state_feature(STATE_NAMES), "action": state_feature(ACTION_NAMES)}


def build_toy_suite(options: SuiteOptions) -> ToySuite:
    """The factory of the toy suite (registered as ``toy``): ``TOY_TASKS`` unless tasks are given.

    Raises:
        UserError: On a placement (the toy suite has none).
        ValueError: On an unknown task or a mode other than ``state``.
    """
    options.refuse_placement()
    return ToySuite(options.task_list(TOY_TASKS), options.observation, options.max_episode_steps)
