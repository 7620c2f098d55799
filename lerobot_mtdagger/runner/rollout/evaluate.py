"""Success per task of a policy, with the pure policy acting (no expert), on evaluation seeds.

``PolicyRunner`` turns a policy and its processors into the batched ``PolicyFn`` the rollouts use,
converting observations as LeRobot's ``preprocess_observation`` does.
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from lerobot_mtdagger.datasets.checkpoints import load_policy
from lerobot_mtdagger.policies import TASK_FEATURE
from lerobot_mtdagger.policies.task_conditioning import TaskOneHotProcessorStep
from lerobot_mtdagger.runner.rollout.collect import EpisodeOptions, PolicyFn, run_episodes, success_by_task
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers, Episode
from lerobot_mtdagger.runner.student import student_of_policy
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.lerobot_compat import dataset_to_policy_features
from lerobot_mtdagger.utils.seeds import EVAL_STREAM


class PolicyRunner:
    """Batched inference: observations + task names -> unnormalised actions (B, action_dim)."""

    tracks_episodes = False
    """Whether the rollouts must say which running episode each row belongs to (``ChunkRunner``)."""

    def __init__(self, policy: Any, preprocessor: Any, postprocessor: Any) -> None:
        """Wraps a policy in eval mode with its processors."""
        self.policy = policy.eval()
        self.preprocessor = preprocessor
        self.postprocessor = postprocessor
        self.input_keys = [key for key in policy.config.input_features if key != TASK_FEATURE]
        self.image_keys = set(policy.config.image_features)
        self.task_aliases: dict[str, str] = {}
        """Task name -> the training task whose input the policy acts with instead (``act_as``)."""

    @classmethod
    def from_pretrained(
        cls, path: str | Path, device: str = "cpu", trust_checkpoint: bool = False
    ) -> PolicyRunner:
        """Loads a pretrained folder or Hub id with its processors, as its type's runner.

        Raises:
            UntrustedCheckpointError: If a processor config names code and the checkpoint is not trusted.
            UserError: If the path is not a complete policy folder or a reachable Hub policy.
        """
        return make_runner(*load_policy(path, device, trust_checkpoint))

    @property
    def task_names(self) -> list[str]:
        """The tasks the policy was trained on: its task embedding's rows or its one-hot positions."""
        names = getattr(self.policy.config, "task_names", None)
        if names:
            return list(names)
        for step in getattr(self.preprocessor, "steps", []):
            if isinstance(step, TaskOneHotProcessorStep):
                return list(step.task_names)
        return []

    @property
    def acts_on_unseen_tasks(self) -> bool:
        """Whether the policy has an input for a task outside ``task_names`` (shared embedding, or zeros)."""
        return getattr(self.policy, "any_task_index", None) is not None

    def act_as(self, aliases: dict[str, str]) -> None:
        """Makes the policy act on each key task with the task input of its value, a training task.

        What ``eval --unseen_rule=nearest`` does for an unseen drawer.

        Raises:
            UserError: If a value is not a task the policy was trained on.
        """
        unknown = sorted({task for task in aliases.values() if task not in self.task_names})
        if unknown:
            raise UserError(f"Cannot act as {unknown}: the policy was trained on {self.task_names}.")
        self.task_aliases = dict(aliases)

    def check_tasks(self, task_names: Sequence[str]) -> None:
        """Refuses tasks the policy cannot act on (``UserError`` naming them, its tasks and the options)."""
        known = self.task_names
        unknown = [name for name in task_names if name not in known and name not in self.task_aliases]
        if unknown and known and not self.acts_on_unseen_tasks:
            raise UserError(
                f"The policy was trained on {known}, not on {unknown}: pass --suite.tasks with tasks it "
                "knows, or evaluate a policy trained with --policy.task_dropout > 0 (its shared embedding "
                "acts on unseen tasks)."
            )

    def check_inputs(self, suite_features: dict[str, dict[str, Any]], obs_mode: str) -> None:
        """Refuses a suite whose observations do not match the policy's inputs (``UserError``)."""
        given_features = dataset_to_policy_features(suite_features)  # images channel-first, as trained
        for key in self.input_keys:
            feature, given = self.policy.config.input_features[key], given_features.get(key)
            if given is None:
                raise UserError(
                    f"The policy takes {key!r}, which --suite.obs_mode={obs_mode} does not give (it gives "
                    f"{sorted(suite_features)}): pass the obs_mode the policy was trained on."
                )
            if tuple(given.shape) != tuple(feature.shape):
                raise UserError(
                    f"The policy takes {key!r} of shape {tuple(feature.shape)}, the suite gives "
                    f"{tuple(given.shape)}: pass the obs_mode, image_size or num_points the policy "
                    "was trained with."
                )

    def __call__(self, observations: list[dict[str, np.ndarray]], tasks: list[str]) -> np.ndarray:
        """Actions for a batch of observations of the given tasks (``KeyError`` on a missing input)."""
        inputs = {
            key: torch.from_numpy(np.stack([observation[key] for observation in observations]))
            for key in self.input_keys
        }
        return self.predict(inputs, tasks).numpy()

    def predict(self, inputs: dict[str, torch.Tensor], tasks: Sequence[str]) -> torch.Tensor:
        """Unnormalised actions (B, action_dim) on the CPU for raw inputs (``KeyError``: an input missing)."""
        with torch.inference_mode():
            action = self.postprocessor(self.policy.select_action(self.preprocess(inputs, tasks)))
        return action.cpu()

    def preprocess(self, inputs: dict[str, torch.Tensor], tasks: Sequence[str]) -> dict[str, Any]:
        """The policy's normalised batch for raw inputs (images to float CHW in [0, 1], as LeRobot's)."""
        batch: dict[str, Any] = {}
        for key in self.input_keys:
            tensor = inputs[key]
            if key in self.image_keys:
                tensor = tensor.permute(0, 3, 1, 2).float() / 255.0
            batch[key] = tensor.float()
        batch["task"] = [self.task_aliases.get(task, task) for task in tasks]
        with torch.inference_mode():
            return self.preprocessor(batch)


def make_runner(policy: Any, preprocessor: Any, postprocessor: Any) -> PolicyRunner:
    """The runner of a policy's student (``UserError`` if no registered student builds its type)."""
    return student_of_policy(policy).make_runner(policy, preprocessor, postprocessor)


@dataclass
class EvalResult:
    """Success of the pure policy per task (and the mean 0-3 progress score where the suite has one)."""

    task_names: list[str]
    success: list[float]
    episodes: list[int]
    progress: list[float] | None = None

    @property
    def mean(self) -> float:
        """Average success over tasks."""
        return float(np.mean(self.success))

    def to_dict(self) -> dict[str, Any]:
        """JSON-ready form."""
        values: dict[str, Any] = {
            "task_names": self.task_names,
            "success": self.success,
            "episodes": self.episodes,
            "mean": self.mean,
        }
        if self.progress is not None:
            values |= {"progress": self.progress, "mean_progress": float(np.mean(self.progress))}
        return values


def evaluate(
    workers: EnvWorkers,
    runner: PolicyFn,
    episodes_per_task: int,
    seed: int,
    steps_after_success: int = 0,
    progress: Callable[[Episode], None] | None = None,
) -> tuple[EvalResult, list[Episode]]:
    """Runs ``episodes_per_task`` pure-policy episodes per task on the evaluation seeds (same every round).

    Episodes end at the first success (plus ``steps_after_success``) or when the env truncates.
    """
    suite = workers.suite
    options = EpisodeOptions(
        beta=0.0,
        seed=seed,
        round_index=0,
        stream=EVAL_STREAM,
        record=False,
        max_steps=None,
        steps_after_success=steps_after_success,
    )
    episodes = run_episodes(
        workers, [episodes_per_task] * len(suite.task_names), options, policy=runner, progress=progress
    )
    rates, counts = success_by_task(episodes, len(suite.task_names))
    task_progress = None
    if suite.reports_progress:
        totals = np.bincount([e.task_index for e in episodes], [e.progress for e in episodes], len(counts))
        task_progress = [float(total / max(count, 1)) for total, count in zip(totals, counts, strict=True)]
    success = [r if r is not None else 0.0 for r in rates]
    return EvalResult(list(suite.task_names), success, counts, task_progress), episodes
