"""One training phase of the multitask policy, with the per-task losses that performance gain needs.

Algorithm 1, "Train Policy": train on D(k) (all committed rounds so far), recording each task's
imitation loss at the start and at the end of the phase, on the training data itself or on a held-out
split of episodes; the gain is ``max(0, L_start - L_end)`` per task.

The rounds are loaded into memory once per phase (round datasets are small and immutable) and
normalised with LeRobot's own pre-processor built from their statistics, the same processor that is
saved with the checkpoint; so what we train, what we roll out and what ``lerobot-eval`` loads agree.
"""

from __future__ import annotations

import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.datasets.lerobot_dataset import LeRobotDataset
from lerobot.datasets.utils import dataset_to_policy_features

from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy, make_mtdagger_pre_post_processors
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import per_task_means

logger = logging.getLogger(__name__)

LOSS_SAMPLES_PER_TASK = 1024


@dataclass
class TrainingData:
    """Frames of several rounds in memory.

    Attributes:
        inputs: Observation tensors by feature key; images stay uint8 (N, H, W, 3), the rest float32.
        action: Expert labels, (N, action_dim) float32.
        task_index: (N,) int64.
        episode_id: (N,) int64, unique per (round, episode).
    """

    inputs: dict[str, torch.Tensor]
    action: torch.Tensor
    task_index: torch.Tensor
    episode_id: torch.Tensor

    def __len__(self) -> int:
        return int(self.action.shape[0])

    def subset(self, index: torch.Tensor) -> TrainingData:
        """The frames at ``index``."""
        return TrainingData(
            inputs={k: v[index] for k, v in self.inputs.items()},
            action=self.action[index],
            task_index=self.task_index[index],
            episode_id=self.episode_id[index],
        )


def load_rounds(roots: Sequence[Path], input_keys: Sequence[str]) -> TrainingData:
    """Loads committed round datasets into memory.

    Args:
        roots: Round dataset folders.
        input_keys: Observation keys the policy reads.

    Returns:
        The concatenated frames.
    """
    parts: dict[str, list[torch.Tensor]] = {
        k: [] for k in [*input_keys, "action", "task_index", "episode_id"]
    }
    for round_position, root in enumerate(roots):
        dataset = LeRobotDataset(f"local/{Path(root).name}", root=root)
        table = dataset.hf_dataset.with_format("numpy")
        for key in input_keys:
            column = table[key]
            if dataset.features[key]["dtype"] == "image":
                column = np.stack([np.asarray(image, dtype=np.uint8) for image in column])
                parts[key].append(torch.from_numpy(column))
            else:
                parts[key].append(torch.from_numpy(np.asarray(column, dtype=np.float32)))
        parts["action"].append(torch.from_numpy(np.asarray(table["action"], dtype=np.float32)))
        parts["task_index"].append(torch.from_numpy(np.asarray(table["task_index"], dtype=np.int64)))
        episode = np.asarray(table["episode_index"], dtype=np.int64)
        parts["episode_id"].append(torch.from_numpy(episode + round_position * 1_000_000))
    merged = {k: torch.cat(v) for k, v in parts.items()}
    return TrainingData(
        inputs={k: merged[k] for k in input_keys},
        action=merged["action"],
        task_index=merged["task_index"],
        episode_id=merged["episode_id"],
    )


def compute_stats(data: TrainingData, image_keys: Sequence[str]) -> dict[str, dict[str, np.ndarray]]:
    """Mean/std/min/max of the vector inputs and the action (point clouds per channel)."""
    stats = {}
    tensors = {k: v for k, v in data.inputs.items() if k not in image_keys} | {"action": data.action}
    for key, tensor in tensors.items():
        flat = tensor.reshape(-1, tensor.shape[-1]).double()
        stats[key] = {
            "mean": flat.mean(0).float().numpy(),
            "std": flat.std(0, unbiased=False).float().numpy(),
            "min": flat.min(0).values.float().numpy(),
            "max": flat.max(0).values.float().numpy(),
        }
    return stats


def policy_config(
    suite_features: dict[str, Any], task_names: Sequence[str], options: Any, device: str = "cpu"
) -> MTDAggerConfig:
    """The ``mtdagger`` config for a suite's features and the run's policy options."""
    features = dataset_to_policy_features(suite_features)
    return MTDAggerConfig(
        device=device,
        task_names=list(task_names),
        input_features={k: f for k, f in features.items() if f.type is not FeatureType.ACTION},
        output_features={"action": PolicyFeature(type=FeatureType.ACTION, shape=features["action"].shape)},
        optimizer_lr=options.lr,
        state_hidden_dims=tuple(options.state_hidden_dims),
        head_hidden_dims=tuple(options.head_hidden_dims),
        pointnet_dims=tuple(options.pointnet_dims),
        task_embedding_dim=options.task_embedding_dim,
        push_to_hub=False,
    )


class NormalisedData:
    """Training frames normalised once with the policy's pre-processor; batches built on demand."""

    def __init__(
        self, data: TrainingData, preprocessor: Any, image_keys: Sequence[str], task_names: Sequence[str]
    ):
        self.data = data
        self.image_keys = list(image_keys)
        self.task_names = list(task_names)
        vector = {k: v for k, v in data.inputs.items() if k not in self.image_keys} | {"action": data.action}
        normalised = preprocessor({**vector, "task": [self.task_names[i] for i in data.task_index.tolist()]})
        self.vector = {k: normalised[k] for k in vector}

    def batch(self, index: torch.Tensor) -> dict[str, Any]:
        """The normalised batch at ``index`` (images as float CHW in [0, 1])."""
        batch: dict[str, Any] = {k: v[index] for k, v in self.vector.items()}
        for key in self.image_keys:
            batch[key] = self.data.inputs[key][index].permute(0, 3, 1, 2).float() / 255.0
        batch["task_index"] = self.data.task_index[index]
        batch["task"] = [self.task_names[i] for i in batch["task_index"].tolist()]
        return batch


@dataclass
class PhaseResult:
    """Per-task losses of one training phase (lists aligned with the task names; None: no sample)."""

    loss_start: list[float | None]
    loss_end: list[float | None]
    gain: list[float]
    train_loss: list[float]
    loss_samples: list[int]


def loss_split(
    data: TrainingData, split: str, heldout_fraction: float, seed: int
) -> tuple[torch.Tensor, torch.Tensor]:
    """Indices of the training frames and of the frames the per-task loss is measured on.

    ``train``: train on everything, measure on up to LOSS_SAMPLES_PER_TASK frames per task.
    ``heldout``: hold out ``heldout_fraction`` of each task's episodes (at least one when the task has
    two or more) and measure on them.
    """
    generator = np.random.default_rng(seed)
    all_index = torch.arange(len(data))
    if split == "heldout":
        heldout_episodes = []
        for task in torch.unique(data.task_index).tolist():
            episodes = np.unique(data.episode_id[data.task_index == task].numpy())
            count = int(round(heldout_fraction * len(episodes)))
            count = min(max(count, 1 if len(episodes) > 1 else 0), len(episodes) - 1)
            heldout_episodes += generator.choice(episodes, size=count, replace=False).tolist()
        held = torch.from_numpy(np.isin(data.episode_id.numpy(), heldout_episodes))
        return all_index[~held], all_index[held]
    measure = []
    for task in torch.unique(data.task_index).tolist():
        task_index = all_index[data.task_index == task].numpy()
        size = min(LOSS_SAMPLES_PER_TASK, len(task_index))
        measure.append(np.sort(generator.choice(task_index, size=size, replace=False)))
    return all_index, torch.from_numpy(np.concatenate(measure))


@torch.no_grad()
def per_task_loss(
    policy: MTDAggerPolicy, data: NormalisedData, index: torch.Tensor, num_tasks: int
) -> tuple[list, list]:
    """Mean MSE per task over the frames at ``index`` (None where a task has none) and the counts."""
    policy.eval()
    sums = torch.zeros(num_tasks, dtype=torch.float64)
    counts = torch.zeros(num_tasks, dtype=torch.float64)
    for chunk in torch.split(index, 4096):
        batch = data.batch(chunk)
        errors = ((policy.predict(batch) - batch["action"]) ** 2).mean(dim=1).double()
        means, chunk_counts = per_task_means(errors, batch["task_index"], num_tasks)
        sums += means * chunk_counts
        counts += chunk_counts
    losses = [float(sums[i] / counts[i]) if counts[i] > 0 else None for i in range(num_tasks)]
    return losses, [int(c) for c in counts.tolist()]


def train_phase(
    policy: MTDAggerPolicy,
    data: NormalisedData,
    train_index: torch.Tensor,
    loss_index: torch.Tensor,
    *,
    steps: int,
    batch_size: int,
    lr: float,
    seed: int,
    on_step: Callable[[int, float], None] | None = None,
) -> PhaseResult:
    """Trains ``policy`` for ``steps`` AdamW steps and measures the per-task loss drop.

    Raises:
        FloatingPointError: If the loss becomes NaN or infinite (nothing is committed then).
    """
    num_tasks = len(data.task_names)
    loss_start, _ = per_task_loss(policy, data, loss_index, num_tasks)
    generator = torch.Generator().manual_seed(seed)
    optimizer = torch.optim.AdamW(
        policy.parameters(), lr=lr, weight_decay=policy.config.optimizer_weight_decay
    )
    policy.train()
    history = []
    for step in range(steps):
        picks = train_index[
            torch.randint(len(train_index), (min(batch_size, len(train_index)),), generator=generator)
        ]
        loss, _ = policy.forward(data.batch(picks))
        if not torch.isfinite(loss):
            raise FloatingPointError(
                f"Training loss became {loss.item()} at step {step}; nothing was committed."
            )
        optimizer.zero_grad()
        loss.backward()
        torch.nn.utils.clip_grad_norm_(policy.parameters(), policy.config.optimizer_grad_clip_norm)
        optimizer.step()
        history.append(loss.item())
        if on_step is not None:
            on_step(step, history[-1])
    loss_end, counts = per_task_loss(policy, data, loss_index, num_tasks)
    gain = [
        max(0.0, start - end) if start is not None and end is not None else 0.0
        for start, end in zip(loss_start, loss_end, strict=True)
    ]
    return PhaseResult(
        loss_start=loss_start, loss_end=loss_end, gain=gain, train_loss=history[-10:], loss_samples=counts
    )


def save_policy(policy: MTDAggerPolicy, preprocessor: Any, postprocessor: Any, folder: Path) -> None:
    """Writes a LeRobot pretrained model folder (config, weights, processors)."""
    policy.save_pretrained(folder)
    preprocessor.save_pretrained(folder)
    postprocessor.save_pretrained(folder)


def build_processors(config: MTDAggerConfig, stats: dict[str, dict[str, np.ndarray]]) -> tuple[Any, Any]:
    """The policy's LeRobot pre- and post-processors for ``stats``."""
    return make_mtdagger_pre_post_processors(config, dataset_stats=stats)
