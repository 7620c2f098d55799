"""MetaWorld's scripted experts (``metaworld.policies.ENV_POLICY_MAP``), keyed by v3 task name."""

from __future__ import annotations

import warnings
from typing import Any

import numpy as np
from metaworld.policies import ENV_POLICY_MAP

from lerobot_mtdagger.utils.errors import UserError

# The scripted policies warn on every step whose proportional gain saturates; the env clips the
# action to [-1, 1] anyway (we clip too), so the warning carries no information.
warnings.filterwarnings("ignore", message=r"Constant\(s\) may be too high", category=UserWarning)


class MetaWorldScriptedExpert:
    """MetaWorld's hand-written policy for one task, acting on the 39-d goal-visible state."""

    def __init__(self, task_name: str) -> None:
        """Builds the scripted policy of ``task_name`` (``ValueError`` if MetaWorld has none)."""
        if task_name not in ENV_POLICY_MAP:
            raise UserError(
                f"MetaWorld has no scripted policy for {task_name!r}; known: {sorted(ENV_POLICY_MAP)}."
            )
        self.task_name = task_name
        self._policy = ENV_POLICY_MAP[task_name]()  # type: ignore[abstract]  # stub: type[Policy]; concrete

    def reset(self) -> None:
        """The scripted policies are stateless."""

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """The scripted action, clipped to the action space [-1, 1]."""
        action = self._policy.get_action(np.asarray(privileged_state, dtype=np.float64))
        return np.clip(action, -1.0, 1.0).astype(np.float32)


def scripted_expert(suite: Any, task_name: str) -> MetaWorldScriptedExpert:
    """The registry's factory for the ``metaworld`` suite family (``experts.registry``)."""
    return MetaWorldScriptedExpert(task_name)
