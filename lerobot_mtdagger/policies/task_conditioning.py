"""How a LeRobot policy without a task input is told its task: a one-hot task vector.

A multitask ACT or Diffusion student reads its task as ``observation.environment_state``, one-hot
over the training tasks (``FeatureType.ENV``: left unnormalised). An unseen task gets the zero
vector, the "any task" input that task dropout trains. ``TaskOneHotProcessorStep``, the first step of
the saved pre-processor, builds it from the ``task`` strings, so a saved student acts on LeRobot's
usual batch; training batches build it from task indices (``task_one_hot``).
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import Any

import torch
from lerobot.configs.types import FeatureType, PipelineFeatureType, PolicyFeature
from lerobot.processor import EnvTransition, ProcessorStep, ProcessorStepRegistry, TransitionKey

TASK_FEATURE = "observation.environment_state"
"""The input a LeRobot student reads its task from (one-hot over the training tasks)."""

ONE_HOT_STEP = "mtdagger_task_one_hot"


def task_feature(num_tasks: int) -> PolicyFeature:
    """The policy feature of the one-hot task vector over ``num_tasks`` training tasks."""
    return PolicyFeature(type=FeatureType.ENV, shape=(num_tasks,))


def task_one_hot(task_index: torch.Tensor, num_tasks: int) -> torch.Tensor:
    """One-hot rows (B, num_tasks) float32 for task indices; an index of -1 gives the zero row."""
    rows = torch.zeros(len(task_index), num_tasks, dtype=torch.float32, device=task_index.device)
    known = task_index >= 0
    rows[known, task_index[known]] = 1.0
    return rows


@ProcessorStepRegistry.register(ONE_HOT_STEP)
class TaskOneHotProcessorStep(ProcessorStep):
    """Writes the one-hot vector of the batch's ``task`` strings into ``observation.environment_state``.

    A task outside ``task_names`` gets the zero vector; a transition without a ``task`` passes unchanged.
    """

    def __init__(self, task_names: Sequence[str] = ()) -> None:
        """Remembers the training tasks, in the order of the one-hot positions."""
        self.task_names = list(task_names)
        self._positions = {name: position for position, name in enumerate(self.task_names)}

    def __call__(self, transition: EnvTransition) -> EnvTransition:
        """Adds the task vector to the observation when the transition names its task(s)."""
        complementary = transition.get(TransitionKey.COMPLEMENTARY_DATA) or {}
        tasks = complementary.get("task")
        observation = transition.get(TransitionKey.OBSERVATION)
        if tasks is None or observation is None:
            return transition
        single = isinstance(tasks, str)
        names = [tasks] if single else list(tasks)
        index = torch.tensor([self._positions.get(name, -1) for name in names], dtype=torch.long)
        vector = task_one_hot(index, len(self.task_names))
        new = dict(transition)
        new[TransitionKey.OBSERVATION] = {**observation, TASK_FEATURE: vector[0] if single else vector}
        return new

    def get_config(self) -> dict[str, Any]:
        """The training tasks (saved with the processor)."""
        return {"task_names": self.task_names}

    def transform_features(
        self, features: dict[PipelineFeatureType, dict[str, PolicyFeature]]
    ) -> dict[PipelineFeatureType, dict[str, PolicyFeature]]:
        """Adds the task vector to the observation features."""
        observation = dict(features.get(PipelineFeatureType.OBSERVATION, {}))
        observation[TASK_FEATURE] = task_feature(len(self.task_names))
        return {**features, PipelineFeatureType.OBSERVATION: observation}
