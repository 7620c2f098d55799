"""The multitask DAgger policy (paper appendix "Multitask Policy Architecture").

h_o = f_enc(o) (PointNet for point clouds, a CNN for images, an MLP for proprioception),
z_i = Embedding(task index), a = f_policy([h_o, z_i]), trained with MSE on the experts' actions.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from typing import Any

import numpy as np
import torch
from lerobot.policies.pretrained import PreTrainedPolicy
from lerobot.utils.constants import ACTION
from torch import Tensor, nn

from lerobot_mtdagger.policies.mtdagger.configuration_mtdagger import MTDAggerConfig

logger = logging.getLogger(__name__)

TASK_KEY = "task"
TASK_INDEX_KEY = "task_index"


def mlp(input_dim: int, hidden_dims: Sequence[int], output_dim: int, dropout: float = 0.0) -> nn.Sequential:
    """Linear-ReLU stack ending in a plain linear layer."""
    layers: list[nn.Module] = []
    previous = input_dim
    for width in hidden_dims:
        layers += [nn.Linear(previous, width), nn.ReLU()]
        if dropout > 0:
            layers.append(nn.Dropout(dropout))
        previous = width
    layers.append(nn.Linear(previous, output_dim))
    return nn.Sequential(*layers)


class ImageEncoder(nn.Module):
    """Small CNN: stride-2 3x3 convolutions with ReLU, global average pool, linear projection."""

    def __init__(self, in_channels: int, channels: Sequence[int], output_dim: int) -> None:
        super().__init__()
        layers: list[nn.Module] = []
        previous = in_channels
        for width in channels:
            layers += [nn.Conv2d(previous, width, kernel_size=3, stride=2, padding=1), nn.ReLU()]
            previous = width
        self.convolutions = nn.Sequential(*layers)
        self.projection = nn.Linear(previous, output_dim)

    def forward(self, image: Tensor) -> Tensor:
        """(B, C, H, W) -> (B, output_dim)."""
        features = self.convolutions(image).mean(dim=(2, 3))  # (B, channels[-1])
        return self.projection(features)


class PointNetEncoder(nn.Module):
    """PointNet: a per-point MLP shared by all points, max-pooled over points, then projected.

    With gradients on, the max-pool is ``max_pool_of_winners`` (same values and gradients, half the cost).
    """

    def __init__(
        self, in_channels: int, dims: Sequence[int], output_dim: int, layer_norm: bool = False
    ) -> None:
        """Builds the per-point MLP (``dims``; the last is the pooled size) and the projection.

        ``in_channels`` is 3 (xyz) or 6 (xyz + rgb); ``layer_norm`` gives DP3's layout.
        """
        super().__init__()
        if layer_norm:
            self.point_mlp = normalised_mlp(in_channels, dims)
            self.projection = nn.Sequential(nn.Linear(dims[-1], output_dim), nn.LayerNorm(output_dim))
        else:
            self.point_mlp = mlp(in_channels, dims[:-1], dims[-1])
            self.projection = nn.Sequential(nn.ReLU(), nn.Linear(dims[-1], output_dim))

    def forward(self, points: Tensor) -> Tensor:
        """(B, N, C) -> (B, output_dim)."""
        if torch.is_grad_enabled():
            pooled = max_pool_of_winners(self.point_mlp, points)
        else:
            pooled = torch.cat(
                [per_point_features(self.point_mlp, c).amax(dim=1) for c in cloud_chunks(points)]
            )
        return self.projection(pooled)


SEARCH_CHUNK_POINTS = 2048
"""Points per chunk of a pass without gradients on a CPU (in cache: 2-3x faster at 512 points)."""


def cloud_chunks(points: Tensor) -> tuple[Tensor, ...]:
    """(B, N, C) split along B into chunks of about SEARCH_CHUNK_POINTS points on a CPU, whole elsewhere.

    On a GPU chunks would only multiply kernel launches (``docs/benchmarks.md``, "On a GPU").
    """
    if points.device.type != "cpu":
        return (points,)
    return points.split(max(1, SEARCH_CHUNK_POINTS // max(1, points.shape[1])))


def per_point_features(per_point: nn.Module, points: Tensor) -> Tensor:
    """``per_point(points)`` without autograd, its ReLUs in place (no copy of each activation)."""
    with torch.no_grad():
        if not isinstance(per_point, nn.Sequential):
            return per_point(points)
        features = points
        for layer in per_point:
            fresh = features is not points  # never write into the caller's tensor
            features = features.relu_() if isinstance(layer, nn.ReLU) and fresh else layer(features)
        return features


def normalised_mlp(input_dim: int, dims: Sequence[int]) -> nn.Sequential:
    """Linear-LayerNorm-ReLU for each size of ``dims`` (DP3's per-point MLP)."""
    layers: list[nn.Module] = []
    previous = input_dim
    for width in dims:
        layers += [nn.Linear(previous, width), nn.LayerNorm(width), nn.ReLU()]
        previous = width
    return nn.Sequential(*layers)


def max_pool_of_winners(per_point: nn.Module, points: Tensor) -> Tensor:
    """``per_point(points).max(dim=1).values`` with a gradient that flows through the winners only.

    Feature c of a pooled cloud depends on the one point that wins c. The per-point network runs
    without autograd on all N points to find the winners, then with autograd on each cloud's distinct
    winners (padded; typically 60-120 of 512 points): values and gradient are the dense max-pool's,
    while backward and stored activations shrink to the winners (``benchmarks/bench_pointnet.py``).
    ``per_point`` must treat points independently (no batch statistics): (B, N, C) -> (B, N, F);
    returns (B, F).
    """
    # (B, F): the winning point of each feature, found a few clouds at a time. ``max(dim).indices`` (the
    # first maximal point, as ``argmax``) reduces over the strided point axis about 1.7x faster on a CPU.
    winners = torch.cat([per_point_features(per_point, c).max(dim=1).indices for c in cloud_chunks(points)])
    ordered, order = winners.sort(dim=1)
    first = torch.ones_like(ordered, dtype=torch.bool)
    first[:, 1:] = ordered[:, 1:] != ordered[:, :-1]
    slot_ordered = first.cumsum(dim=1) - 1  # position of each feature's winner among the distinct ones
    distinct = int(slot_ordered.max()) + 1
    unique = torch.zeros(winners.shape[0], distinct, dtype=torch.long, device=points.device)
    unique.scatter_(1, slot_ordered, ordered)  # (B, distinct); padding repeats point 0, never read
    slot = torch.empty_like(slot_ordered).scatter_(1, order, slot_ordered)  # (B, F)
    gathered = torch.gather(points, 1, unique[..., None].expand(-1, -1, points.shape[-1]))
    features = per_point(gathered)  # (B, distinct, F)
    return torch.gather(features, 1, slot[:, None, :]).squeeze(1)


def encoder_name(key: str) -> str:
    """The ``encoders`` entry of an input feature (module names cannot hold dots)."""
    return key.replace(".", "_")


def build_encoder(key: str, config: MTDAggerConfig) -> tuple[nn.Module, int]:
    """The encoder of one input feature and its output size (PointNet, CNN or MLP by feature kind)."""
    if key in config.pointcloud_features:
        channels = config.pointcloud_features[key].shape[1]
        encoder = PointNetEncoder(
            channels, config.pointnet_dims, config.pointcloud_embedding_dim, config.pointnet_layer_norm
        )
        return encoder, config.pointcloud_embedding_dim
    if key in config.image_features:
        channels = config.image_features[key].shape[0]
        return ImageEncoder(
            channels, config.image_channels, config.image_embedding_dim
        ), config.image_embedding_dim
    size = int(np.prod(config.vector_features[key].shape))
    return mlp(size, config.state_hidden_dims, config.state_embedding_dim), config.state_embedding_dim


class MTDAggerPolicy(PreTrainedPolicy):
    """Multitask policy conditioned on a learned task embedding (LeRobot policy type ``mtdagger``)."""

    config_class = MTDAggerConfig
    name = "mtdagger"

    def __init__(self, config: MTDAggerConfig, dataset_meta: Any = None, **kwargs: Any) -> None:
        """Builds the encoders the input features call for.

        Args:
            config: The policy config; an empty ``task_names`` is filled from ``dataset_meta``.
            dataset_meta: LeRobot dataset metadata (passed by ``make_policy``), for the task vocabulary.
            **kwargs: Other ``make_policy`` arguments, unused (normalisation lives in the processors).

        Raises:
            ValueError: On a config without usable inputs, action or task vocabulary.
        """
        super().__init__(config)
        if not config.task_names and dataset_meta is not None:
            tasks = dataset_meta.tasks  # DataFrame indexed by task string, column task_index
            config.task_names = [str(t) for t in tasks.sort_values("task_index").index]
        config.validate_features()
        self.config = config
        self._task_lookup = {name: i for i, name in enumerate(config.task_names)}
        # Row len(task_names): the shared "any task" embedding, present only with task dropout.
        self.any_task_index = len(config.task_names) if config.task_dropout > 0 else None
        rows = len(config.task_names) + int(self.any_task_index is not None)
        self.task_embedding = nn.Embedding(rows, config.task_embedding_dim)
        self._unseen_logged: set[str] = set()
        fused = config.task_embedding_dim

        # One encoder per input feature, keyed by it (as SB3's CombinedExtractor); their outputs are
        # concatenated after the task embedding in this order: vectors, images, point clouds.
        self.vector_keys = sorted(config.vector_features)
        self.image_keys = sorted(config.image_features)
        self.pointcloud_keys = sorted(config.pointcloud_features)
        self.encoders = nn.ModuleDict()
        for key in [*self.vector_keys, *self.image_keys, *self.pointcloud_keys]:
            encoder, size = build_encoder(key, config)
            self.encoders[encoder_name(key)] = encoder
            fused += size
        self._register_load_state_dict_pre_hook(self._migrate_checkpoint)

        action_dim = config.output_features[ACTION].shape[0]
        self.head = mlp(fused, config.head_hidden_dims, action_dim, dropout=config.dropout)

    def _migrate_checkpoint(self, state_dict: dict[str, Tensor], prefix: str, *args: Any) -> None:
        """Renames a checkpoint's weights in place to ``encoders.<key>`` (``ValueError`` if unmappable)."""
        renames: dict[str, list[str]] = {}
        if any(name.startswith(f"{prefix}state_encoder.") for name in state_dict):
            if len(self.vector_keys) != 1:
                raise ValueError(
                    f"This checkpoint's state encoder read {self.vector_keys} concatenated; encoders are now "
                    "one per input: retrain the policy (or load it with lerobot-mtdagger before 0.2)."
                )
            renames["state_encoder."] = [encoder_name(self.vector_keys[0])]
        renames["image_encoder."] = [encoder_name(k) for k in self.image_keys]
        for index, key in enumerate(self.pointcloud_keys):
            renames[f"pointcloud_encoders.{index}."] = [encoder_name(key)]
        for old, targets in renames.items():
            for name in [n for n in state_dict if n.startswith(prefix + old)]:
                tensor = state_dict.pop(name)
                for target in targets:
                    state_dict[f"{prefix}encoders.{target}.{name[len(prefix + old) :]}"] = tensor

    # ---------------------------------------------------------------------------------------------
    # Task conditioning
    # ---------------------------------------------------------------------------------------------

    def task_indices(self, batch: dict[str, Any]) -> Tensor:
        """Task index per sample, from ``task`` strings or ``task_index`` (``ValueError``: unknown, none)."""
        device = self.task_embedding.weight.device
        tasks = batch.get(TASK_KEY)
        if tasks is not None:
            if isinstance(tasks, str):
                tasks = [tasks]
            unknown = sorted({t for t in tasks if t not in self._task_lookup})
            if unknown and self.any_task_index is None:
                raise ValueError(
                    f"Unknown task(s) {unknown}: this policy was trained on {self.config.task_names} "
                    "(a policy trained with --policy.task_dropout > 0 acts on unseen tasks)."
                )
            for task in set(unknown) - self._unseen_logged:
                logger.info("Task %r is not a training task: the shared embedding acts on it.", task)
                self._unseen_logged.add(task)
            indices = [self._task_lookup.get(t, self.any_task_index) for t in tasks]
            return torch.tensor(indices, device=device, dtype=torch.long)
        if TASK_INDEX_KEY in batch:
            index = torch.as_tensor(batch[TASK_INDEX_KEY], device=device).long().reshape(-1)
            if index.numel() and (index.min() < 0 or index.max() >= len(self.config.task_names)):
                raise ValueError(
                    f"task_index out of range [0, {len(self.config.task_names)}): {index.tolist()}."
                )
            return index
        raise ValueError("The batch has neither 'task' strings nor 'task_index': the policy needs the task.")

    # ---------------------------------------------------------------------------------------------
    # Network
    # ---------------------------------------------------------------------------------------------

    def predict(self, batch: dict[str, Any], *, task_index: Tensor | None = None) -> Tensor:
        """Normalised action for a normalised observation batch, (B, action_dim).

        ``task_index`` (B,) replaces the batch's task information; it is trusted, not validated, so there
        is no host-device sync.
        """
        if task_index is None:
            task_index = self.task_indices(batch)
        if self.training and self.any_task_index is not None:
            # Task dropout: some samples learn the shared "any task" embedding instead of their own.
            dropped = torch.rand(task_index.shape, device=task_index.device) < self.config.task_dropout
            task_index = torch.where(dropped, torch.full_like(task_index, self.any_task_index), task_index)
        features = [self.task_embedding(task_index)]
        features += [self.encoders[encoder_name(k)](batch[k].flatten(start_dim=1)) for k in self.vector_keys]
        features += [
            self.encoders[encoder_name(k)](batch[k]) for k in (*self.image_keys, *self.pointcloud_keys)
        ]
        batch_size = features[0].shape[0]
        for feature in features[1:]:
            if feature.shape[0] != batch_size:
                raise ValueError(f"Batch has {feature.shape[0]} observations but {batch_size} task entries.")
        return self.head(torch.cat(features, dim=1))

    def imitation_loss(self, batch: dict[str, Any], *, task_index: Tensor | None = None) -> Tensor:
        """Mean squared error to the expert action over the batch: the training objective (with its graph).

        The lean path of :meth:`forward`: no per-task statistics and, with ``task_index`` (trusted, as in
        :meth:`predict`), no host-device sync.
        """
        loss, _ = self._imitation_terms(batch, task_index)
        return loss

    def _imitation_terms(self, batch: dict[str, Any], task_index: Tensor | None) -> tuple[Tensor, Tensor]:
        """The loss and the prediction it was computed from."""
        prediction = self.predict(batch, task_index=task_index)
        return nn.functional.mse_loss(prediction, batch[ACTION]), prediction

    def forward(self, batch: dict[str, Any]) -> tuple[Tensor, dict[str, Any]]:
        """MSE to the expert action, overall and per task (LeRobot's training entry point).

        Returns:
            The mean loss, and ``{"loss", "per_task_loss": {task: loss}, "per_task_count": {task: samples}}``
            for the tasks in the batch (a few host-device syncs: the training loop calls it at log intervals).
        """
        indices = self.task_indices(batch)
        loss, prediction = self._imitation_terms(batch, indices)
        per_sample = ((prediction.detach() - batch[ACTION]) ** 2).mean(dim=1)  # (B,)
        known = indices < len(self.config.task_names)  # unseen tasks (shared embedding) have no entry
        per_task, counts = per_task_means(per_sample[known], indices[known], len(self.config.task_names))
        present = torch.nonzero(counts).flatten().tolist()
        names = self.config.task_names
        per_task_values = per_task.tolist()
        count_values = counts.tolist()
        return loss, {
            "loss": loss.item(),
            "per_task_loss": {names[i]: per_task_values[i] for i in present},
            "per_task_count": {names[i]: int(count_values[i]) for i in present},
        }

    @torch.no_grad()
    def predict_action_chunk(self, batch: dict[str, Any], **kwargs: Any) -> Tensor:
        """A one-step chunk, (B, 1, action_dim)."""
        return self.predict(batch).unsqueeze(1)

    @torch.no_grad()
    def select_action(self, batch: dict[str, Any], **kwargs: Any) -> Tensor:
        """The action for each observation of the batch, (B, action_dim), in eval mode."""
        if self.training:
            self.eval()
        return self.predict(batch)

    def reset(self) -> None:
        """The policy has no per-episode state."""

    def get_optim_params(self) -> dict:
        """All parameters, one group."""
        return self.parameters()


def per_task_means(values: Tensor, task_index: Tensor, num_tasks: int) -> tuple[Tensor, Tensor]:
    """Mean of ``values`` (B,) per task index and the sample count per task, each (num_tasks,)."""
    sums = torch.zeros(num_tasks, device=values.device, dtype=values.dtype).index_add_(0, task_index, values)
    counts = torch.zeros(num_tasks, device=values.device, dtype=values.dtype).index_add_(
        0, task_index, torch.ones_like(values)
    )
    return sums / counts.clamp(min=1), counts
