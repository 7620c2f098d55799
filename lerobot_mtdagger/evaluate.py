"""Success per task of a policy, with the pure policy acting (no expert), on evaluation seeds.

``PolicyRunner`` turns a LeRobot pretrained ``mtdagger`` policy and its processors into the batched
``PolicyFn`` the rollouts use; observations are converted exactly as LeRobot's
``preprocess_observation`` does (images to float CHW in [0, 1]).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch

from lerobot_mtdagger.checkpoints import load_policy
from lerobot_mtdagger.collect import PolicyFn, run_episodes, success_by_task
from lerobot_mtdagger.errors import UserError
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.seeds import EVAL_STREAM
from lerobot_mtdagger.workers import EnvWorkers, Episode


class PolicyRunner:
    """Batched inference: observations + task names -> unnormalised actions (B, action_dim)."""

    def __init__(self, policy: MTDAggerPolicy, preprocessor: Any, postprocessor: Any) -> None:
        """Wraps a policy in eval mode with its processors."""
        self.policy = policy.eval()
        self.preprocessor = preprocessor
        self.postprocessor = postprocessor
        self.input_keys = list(policy.config.input_features)
        self.image_keys = set(policy.config.image_features)

    @classmethod
    def from_pretrained(
        cls, path: str | Path, device: str = "cpu", trust_checkpoint: bool = False
    ) -> PolicyRunner:
        """Loads a pretrained model folder or Hub id with its saved processors (``load_policy``).

        Raises:
            UntrustedCheckpointError: If a processor config names code and the checkpoint is not trusted.
            UserError: If the path is not a complete ``mtdagger`` policy folder or a reachable Hub
                policy, naming the path or file and the fix.
        """
        return cls(*load_policy(path, device, trust_checkpoint))

    def check_inputs(self, suite_features: dict[str, dict[str, Any]], obs_mode: str) -> None:
        """Refuses a suite whose observations do not match the policy's inputs (key and shape).

        Raises:
            UserError: Naming the input, both shapes and the option to change.
        """
        for key, feature in self.policy.config.input_features.items():
            given = suite_features.get(key)
            if given is None:
                raise UserError(
                    f"The policy takes {key!r}, which --obs_mode={obs_mode} does not give (it gives "
                    f"{sorted(suite_features)}): pass the obs_mode the policy was trained on."
                )
            if tuple(given["shape"]) != tuple(feature.shape):
                raise UserError(
                    f"The policy takes {key!r} of shape {tuple(feature.shape)}, the suite gives "
                    f"{tuple(given['shape'])}: pass the obs_mode, image_size or num_points the policy "
                    "was trained with."
                )

    def __call__(self, observations: list[dict[str, np.ndarray]], tasks: list[str]) -> np.ndarray:
        """Actions for a batch of observations of the given tasks.

        Raises:
            KeyError: If an observation lacks an input the policy was trained on.
        """
        inputs = {
            key: torch.from_numpy(np.stack([observation[key] for observation in observations]))
            for key in self.input_keys
        }
        return self.predict(inputs, tasks).numpy()

    def predict(self, inputs: dict[str, torch.Tensor], tasks: Sequence[str]) -> torch.Tensor:
        """Unnormalised actions (B, action_dim) on the CPU for batched raw inputs.

        Args:
            inputs: Raw observation tensors by key, images uint8 (B, H, W, 3) as stored.
            tasks: Task name of each row.

        Raises:
            KeyError: If an input the policy was trained on is missing.
        """
        batch: dict[str, Any] = {}
        for key in self.input_keys:
            tensor = inputs[key]
            if key in self.image_keys:
                tensor = tensor.permute(0, 3, 1, 2).float() / 255.0
            batch[key] = tensor.float()
        batch["task"] = list(tasks)
        with torch.inference_mode():
            action = self.postprocessor(self.policy.select_action(self.preprocessor(batch)))
        return action.cpu()


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
    """Runs ``episodes_per_task`` pure-policy episodes per task on the evaluation seeds.

    Episodes end at the first success or when the env truncates (its max episode length). The
    evaluation seeds do not depend on the round, so every round is evaluated on the same episodes.

    Args:
        workers: The env workers (their suite gives the tasks).
        runner: The policy.
        episodes_per_task: Episodes per task.
        seed: Experiment seed (the evaluation seeds derive from it).
        steps_after_success: Steps run after the first success.
        progress: Called with each finished episode.
    """
    suite = workers.suite
    episodes = run_episodes(
        workers,
        [episodes_per_task] * len(suite.task_names),
        policy=runner,
        beta=0.0,
        seed=seed,
        round_index=0,
        stream=EVAL_STREAM,
        record=False,
        max_steps=None,
        steps_after_success=steps_after_success,
        progress=progress,
    )
    rates, counts = success_by_task(episodes, len(suite.task_names))
    progress = None
    if suite.reports_progress:
        totals = np.bincount([e.task_index for e in episodes], [e.progress for e in episodes], len(counts))
        progress = [float(total / max(count, 1)) for total, count in zip(totals, counts, strict=True)]
    success = [r if r is not None else 0.0 for r in rates]
    return EvalResult(list(suite.task_names), success, counts, progress), episodes
