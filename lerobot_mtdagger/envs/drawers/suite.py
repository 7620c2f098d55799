"""The drawer suite: LeRobot-keyed envs (``DrawerTaskEnv``) and the ``DrawerSuite`` that builds them."""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import numpy as np

from lerobot_mtdagger.envs.base import ObservationConfig, TaskSuite, observation_features
from lerobot_mtdagger.envs.drawers.catalogue import DRAWER_TASKS, HELDOUT_TASKS, VARIANTS
from lerobot_mtdagger.envs.drawers.scene import DrawerSceneEnv
from lerobot_mtdagger.envs.drawers.variants import (
    DRAWER_STATE_NAMES,
    PLACEMENTS,
    STATE_INDEX,
    DrawerVariant,
    Placement,
    nearest_variant,
    placement_named,
)
from lerobot_mtdagger.envs.metaworld import ACTION_DIM, ACTION_NAMES, PROPRIO_NAMES, MetaWorldTaskEnv
from lerobot_mtdagger.envs.registry import SuiteOptions
from lerobot_mtdagger.envs.rendering import CropBox
from lerobot_mtdagger.utils.errors import UserError

DRAWER_CROP = CropBox(low=(-0.62, 0.3, 0.005), high=(0.62, 0.975, 0.55))


def drawer_state_names(config: ObservationConfig) -> list[str]:
    """Names of ``observation.state``: privileged state in ``state`` mode, else hand xyz + gripper."""
    return DRAWER_STATE_NAMES if config.obs_mode == "state" else PROPRIO_NAMES


class DrawerTaskEnv(MetaWorldTaskEnv):
    """One drawer with LeRobot-keyed observations (see the ``lerobot_mtdagger.envs.drawers`` docstring)."""

    default_crop = DRAWER_CROP

    def __init__(
        self,
        variant: DrawerVariant,
        observation: ObservationConfig,
        seed: int | None = None,
        max_episode_steps: int | None = None,
        placement: Placement | None = None,
    ) -> None:
        """Builds the drawer's model and env (placed per reset by ``placement``, default if None)."""
        self.variant = variant
        self.placement = placement_named(None) if placement is None else placement
        super().__init__(variant.name, observation, seed=seed, max_episode_steps=max_episode_steps)

    def _build_raw_env(self) -> DrawerSceneEnv:
        return DrawerSceneEnv(self.variant, self.placement)

    def state_names(self) -> list[str]:
        """Privileged state names in ``state`` mode, hand xyz + gripper otherwise."""
        return drawer_state_names(self.observation_config)

    def _proprio_state(self, raw: np.ndarray) -> np.ndarray:
        return raw[:4]

    def _step_info(self, raw: np.ndarray, raw_info: dict[str, Any]) -> dict[str, Any]:
        info = super()._step_info(raw, raw_info)
        info["progress"] = int(raw_info.get("progress", 0))
        info["opening"] = float(raw[STATE_INDEX["opening"]])
        return info


class DrawerSuite(TaskSuite):
    """The drawer-opening suite: 11 training drawers, held-out drawers for evaluation."""

    name = "drawers"
    expert_family = "drawers"
    reports_progress = True

    def __init__(
        self,
        task_names: Sequence[str],
        observation: ObservationConfig,
        max_episode_steps: int | None = None,
        variants: Sequence[DrawerVariant] | None = None,
        placement: str | Placement | None = None,
    ) -> None:
        """Selects the drawers of the suite.

        Args:
            task_names: Training drawers (of ``DRAWER_TASKS``, ``HELDOUT_TASKS`` or ``variants``).
            observation: What the envs show the policy.
            max_episode_steps: Truncation length (None: ``MAX_EPISODE_STEPS``).
            variants: Extra user-defined drawer variants that task names may refer to.
            placement: A ``PLACEMENTS`` name or a ``Placement`` (None: ``DEFAULT_PLACEMENT``).

        Raises:
            ValueError: On an unknown drawer or placement.
        """
        self.placement = placement if isinstance(placement, Placement) else placement_named(placement)
        self.variants = dict(VARIANTS)
        for variant in variants or ():
            self.variants[variant.name] = variant
        unknown = [t for t in task_names if t not in self.variants]
        if unknown:
            raise ValueError(f"Unknown drawer(s) {unknown}; known drawers: {sorted(self.variants)}.")
        super().__init__(task_names, observation)
        self.max_episode_steps = max_episode_steps
        self.heldout_task_names = [t for t in HELDOUT_TASKS if t not in self.task_names]
        self._user_variants = list(variants or ())

    def heldout_suite(self) -> DrawerSuite | None:
        """The unseen drawers as a suite of their own (for evaluation: the policy has no index for them)."""
        if not self.heldout_task_names:
            return None
        return DrawerSuite(
            self.heldout_task_names,
            self.observation,
            self.max_episode_steps,
            variants=self._user_variants,
            placement=self.placement,
        )

    def nearest_training_task(self, task_name: str, training_tasks: Sequence[str]) -> str:
        """The training drawer whose handle is most like the unseen ``task_name``'s (``UserError``: none)."""
        variant = self.variants[task_name]
        known = [self.variants[name] for name in training_tasks if name in self.variants]
        nearest = nearest_variant(variant, known)
        if nearest is None:
            raise UserError(
                f"No training drawer has a {variant.handle} handle like {task_name!r} (trained on "
                f"{list(training_tasks)}): evaluate it with --unseen_rule=shared."
            )
        return nearest.name

    @property
    def action_dim(self) -> int:
        """MetaWorld's 4-d action: end-effector displacement xyz and gripper effort."""
        return ACTION_DIM

    def make_env(self, task_name: str, seed: int | None = None) -> DrawerTaskEnv:
        """Builds the env of a training or held-out drawer."""
        self.check_buildable(task_name)
        variant = self.variants[task_name]
        return DrawerTaskEnv(
            variant,
            self.observation,
            seed=seed,
            max_episode_steps=self.max_episode_steps,
            placement=self.placement,
        )

    @property
    def features(self) -> dict[str, dict[str, Any]]:
        """LeRobot features of the observations of the current mode, plus ``action``."""
        return observation_features(self.observation, drawer_state_names(self.observation), ACTION_NAMES)


def build_drawer_suite(options: SuiteOptions) -> DrawerSuite:
    """The factory of the drawer suite (registered as ``drawers``): ``DRAWER_TASKS`` unless tasks are given.

    Raises:
        UserError: On a placement that is not one of ``PLACEMENTS``.
        ValueError: On an unknown drawer.
    """
    if options.placement is not None and options.placement not in PLACEMENTS:
        raise UserError(
            f"Unknown drawer placement {options.placement!r}; choose one of {sorted(PLACEMENTS)}."
        )
    return DrawerSuite(
        options.task_list(DRAWER_TASKS),
        options.observation,
        max_episode_steps=options.max_episode_steps,
        placement=options.placement,
    )
