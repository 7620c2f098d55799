r"""Our suites as a LeRobot env plugin, so stock ``lerobot-eval`` can evaluate a policy on one task.

Usage::

    lerobot-eval --policy.path=<checkpoint>/pretrained_model \
        --env.discover_packages_path=lerobot_mtdagger.envs --env.type=mtdagger_suite \
        --env.suite.name=metaworld-mt10 --env.task=reach-v3 --eval.n_episodes=10 --eval.batch_size=1

The type name avoids "metaworld", which LeRobot routes to its own code. A point cloud arrives as
``environment_state`` (the keys LeRobot keeps): evaluate a point-cloud policy with
``--rename_map='{"observation.environment_state": "observation.pointcloud"}'``. Episodes end at
the first success.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass, field
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium.envs.registration import register, registry
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.envs.configs import EnvConfig

# Importing the policies registers the ``mtdagger`` policy type: lerobot-eval decodes the checkpoint's
# config before it could honour a --policy.discover_packages_path (LeRobot 0.4.4 passes that flag on
# to the config as an unknown field when --policy.path is given), so the env plugin brings it along.
import lerobot_mtdagger.policies  # noqa: F401
from lerobot_mtdagger.envs import IMAGE_KEY, POINTCLOUD_KEY, STATE_KEY, SuiteConfig, suite_from_config

GYM_ID = "MTDAgger/Suite-v0"
RAW_KEYS = {STATE_KEY: "agent_pos", IMAGE_KEY: "pixels", POINTCLOUD_KEY: "environment_state"}


class LeRobotSuiteEnv(gym.Env):
    """One task of a suite with LeRobot's raw observation keys; terminates at the first success."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 80}

    def __init__(self, render_mode: str | None = "rgb_array", **suite_options: Any) -> None:
        """Builds the suite env of one task.

        Args:
            render_mode: Gymnasium's render mode (``rgb_array``).
            **suite_options: ``MTDAggerSuiteEnvConfig.gym_kwargs``: ``suite`` and ``task``.

        Raises:
            TypeError: On an option that is not such a field.
            ValueError: If ``task`` is None.
        """
        config = MTDAggerSuiteEnvConfig(**suite_options)
        task = config.task
        self._suite = suite_from_config(config.task_suite)
        if task is None:  # every suite's make_env refuses it (ValueError)
            raise ValueError("LeRobotSuiteEnv runs one task: give --env.task, got None.")
        # A suite's task env: a gym.Env with ``max_episode_steps`` and a ``Dict`` observation space.
        env: Any = self._suite.make_env(task)
        self._env = env
        self.task_description = task
        self.task = task  # LeRobot 0.6 warns on every eval unless an env has both
        self.render_mode = render_mode
        self._max_episode_steps = self._env.max_episode_steps
        self.action_space = self._env.action_space
        self.observation_space = gym.spaces.Dict(
            {RAW_KEYS[k]: space for k, space in self._env.observation_space.spaces.items()}
        )

    @staticmethod
    def _raw(observation: dict[str, np.ndarray]) -> dict[str, np.ndarray]:
        return {RAW_KEYS[k]: v for k, v in observation.items()}

    def reset(self, *, seed: int | None = None, options: dict | None = None) -> tuple[dict, dict]:
        """Resets the task env."""
        observation, info = self._env.reset(seed=seed)
        return self._raw(observation), {"is_success": False}

    def step(self, action: np.ndarray) -> tuple[dict, float, bool, bool, dict]:
        """Steps the task env; ``terminated`` at the first success."""
        observation, reward, _, truncated, info = self._env.step(action)
        success = bool(info["success"])
        return self._raw(observation), reward, success, truncated, {"is_success": success}

    def render(self) -> np.ndarray:
        """An RGB frame for LeRobot's eval videos."""
        return self._env.render()

    def close(self) -> None:
        """Closes the task env."""
        self._env.close()


if GYM_ID not in registry:
    # No order-enforcing wrapper: lerobot-eval reads task_description off the env itself.
    register(
        id=GYM_ID, entry_point=f"{__name__}:LeRobotSuiteEnv", order_enforce=False, disable_env_checker=True
    )


def _plugin_suite() -> SuiteConfig:
    """The plugin's default suite: MT10 on state (``--env.suite.name``, ``--env.suite.obs_mode``)."""
    return SuiteConfig(name="metaworld-mt10", obs_mode="state")


@EnvConfig.register_subclass("mtdagger_suite")
@dataclass
class MTDAggerSuiteEnvConfig(EnvConfig):
    """``--env.type=mtdagger_suite``: one task of a lerobot-mtdagger suite for ``lerobot-eval``.

    Attributes:
        suite: The suite and its observations (``--env.suite.name=drawers --env.suite.obs_mode=pointcloud``);
            ``obs_mode`` must match the policy's; ``suite.tasks`` is not used.
        task: Task name within the suite (also the task string handed to the policy).
    """

    suite: SuiteConfig = field(default_factory=_plugin_suite)
    task: str | None = "reach-v3"
    fps: int = 80
    features: dict[str, PolicyFeature] = field(default_factory=dict)
    features_map: dict[str, str] = field(default_factory=dict)

    def __post_init__(self) -> None:
        if isinstance(self.suite, dict):  # gym_kwargs hand the suite over as a mapping
            self.suite = SuiteConfig(**self.suite)
        defaults = _plugin_suite()  # draccus builds a SuiteConfig of class defaults when one field is given
        self.suite.name = self.suite.name or defaults.name
        self.suite.obs_mode = self.suite.obs_mode or defaults.obs_mode
        suite = suite_from_config(self.task_suite)
        self.features, self.features_map = {}, {}
        for key, feature in suite.features.items():
            if key == "action":
                self.features["action"] = PolicyFeature(
                    type=FeatureType.ACTION, shape=tuple(feature["shape"])
                )
                self.features_map["action"] = "action"
                continue
            raw = RAW_KEYS[key]
            shape = tuple(feature["shape"])
            feature_type = FeatureType.VISUAL if feature["dtype"] == "image" else FeatureType.STATE
            self.features[raw] = PolicyFeature(type=feature_type, shape=shape)
            self.features_map[raw] = key if key != POINTCLOUD_KEY else "observation.environment_state"

    @property
    def task_suite(self) -> SuiteConfig:
        """``suite`` narrowed to the one task (all the suite's tasks when ``task`` is None)."""
        return dataclasses.replace(self.suite, tasks=[self.task] if self.task else [])

    @property
    def package_name(self) -> str:
        """The module that registers the gym id."""
        return __name__

    @property
    def gym_id(self) -> str:
        """One gym id for every suite and task; ``gym_kwargs`` select them."""
        return GYM_ID

    @property
    def gym_kwargs(self) -> dict[str, Any]:
        """Arguments of ``LeRobotSuiteEnv``: the task and the suite's options."""
        return {"suite": dataclasses.asdict(self.suite), "task": self.task}
