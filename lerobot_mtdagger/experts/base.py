"""The ``Expert`` protocol and the adapters that turn other policies into experts.

An expert acts on the env's privileged state (``info["privileged_state"]``), never on the learner's
observation. A function ``f(privileged_state) -> action`` becomes one with ``CallableExpert``; a
LeRobot policy trained on the privileged state as ``observation.state`` with ``LeRobotPolicyExpert``;
hand either to ``suite.with_experts({"reach-v3": my_expert})``.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol, runtime_checkable

import numpy as np


@runtime_checkable
class Expert(Protocol):
    """A task expert: reset at each episode start, then one action per step."""

    def reset(self) -> None:
        """Clears any per-episode state."""

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """Returns the action for one privileged state (1-D), as a float32 vector."""


class CallableExpert:
    """Adapts a stateless function ``f(privileged_state) -> action`` to the ``Expert`` protocol."""

    def __init__(
        self, function: Callable[[np.ndarray], Any], reset: Callable[[], None] | None = None
    ) -> None:
        """Wraps ``function``; ``reset`` (optional) runs at each episode start."""
        if not callable(function):
            raise TypeError(f"CallableExpert needs a callable, got {type(function).__name__}.")
        self._function = function
        self._reset = reset

    def reset(self) -> None:
        """Runs the optional reset hook."""
        if self._reset is not None:
            self._reset()

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """Calls the function."""
        return np.asarray(self._function(privileged_state), dtype=np.float32)


class LeRobotPolicyExpert:
    """Uses a LeRobot ``PreTrainedPolicy`` trained on the privileged state as an expert.

    The privileged state is fed as ``observation.state`` (batch of one); the pre- and
    post-processors of the policy normalise inputs and unnormalise the action.
    """

    def __init__(
        self,
        policy: Any,
        preprocessor: Callable[[dict], dict] | None = None,
        postprocessor: Callable[[Any], Any] | None = None,
        state_key: str = "observation.state",
        task: str | None = None,
    ) -> None:
        """Wraps a loaded policy (put it in eval mode on the device of your choice first)."""
        self.policy = policy
        self.preprocessor = preprocessor
        self.postprocessor = postprocessor
        self.state_key = state_key
        self.task = task

    def reset(self) -> None:
        """Clears the policy's action queue."""
        self.policy.reset()

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """Runs ``select_action`` on the state."""
        import torch

        state = torch.as_tensor(np.asarray(privileged_state, dtype=np.float32))[None]
        batch: dict[str, Any] = {self.state_key: state}
        if self.task is not None:
            batch["task"] = [self.task]
        if self.preprocessor is not None:
            batch = self.preprocessor(batch)
        with torch.inference_mode():
            action = self.policy.select_action(batch)
        if self.postprocessor is not None:
            action = self.postprocessor(action)
        return action.detach().cpu().numpy().reshape(-1).astype(np.float32)


class ActionCheckedExpert:
    """Checks an expert's output: a finite vector of the task's action size."""

    def __init__(self, expert: Expert, task_name: str, action_dim: int) -> None:
        """Wraps ``expert`` (``TypeError`` if it lacks ``reset``/``act``)."""
        if not isinstance(expert, Expert):
            raise TypeError(
                f"The expert for {task_name!r} is a {type(expert).__name__} without reset() and "
                "act(privileged_state); wrap a function with CallableExpert or a LeRobot policy with "
                "LeRobotPolicyExpert."
            )
        self.expert = expert
        self.task_name = task_name
        self.action_dim = action_dim

    def reset(self) -> None:
        """Resets the wrapped expert."""
        self.expert.reset()

    def act(self, privileged_state: np.ndarray) -> np.ndarray:
        """The wrapped expert's action, checked (``ValueError`` on a wrong size or a non-finite value)."""
        action = np.asarray(self.expert.act(privileged_state), dtype=np.float32).reshape(-1)
        if action.shape != (self.action_dim,):
            raise ValueError(
                f"The expert for task {self.task_name!r} returned an action of size {action.size}, but "
                f"the task's action space has size {self.action_dim}; fix the expert's output."
            )
        if not np.all(np.isfinite(action)):
            raise ValueError(f"The expert for task {self.task_name!r} returned a non-finite action {action}.")
        return action


@dataclass
class ExpertEpisode:
    """Outcome of one expert episode: success at any step, and the step of the first success."""

    seed: int
    success: bool
    steps: int


def run_expert_episode(
    env: Any, expert: Expert, seed: int, stop_on_success: bool = True, noise: Any = None
) -> ExpertEpisode:
    """Runs ``expert`` for one seeded episode of ``env`` (the expert always acts).

    ``stop_on_success`` ends the episode at the first success (MetaWorld's success does not persist);
    ``noise`` is the episode's ``ActionNoise``, added to every action (None: the expert as it is). The
    outcome's ``steps`` is the episode length.
    """
    _, info = env.reset(seed=seed)
    expert.reset()
    success, steps = False, 0
    while True:
        action = expert.act(info["privileged_state"])
        if noise is not None:
            action, _ = noise.perturb(action)
        _, _, terminated, truncated, info = env.step(action)
        steps += 1
        success = success or bool(info["success"])
        if terminated or truncated or (success and stop_on_success):
            return ExpertEpisode(seed=seed, success=success, steps=steps)
