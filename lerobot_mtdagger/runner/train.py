"""One training phase of the multitask policy, with the per-task losses that performance gain needs.

Algorithm 1, "Train Policy": train on D(k) (all committed rounds so far), recording each task's
imitation loss at the start and at the end of the phase, on the training data itself or on a held-out
split of episodes; the gain is ``max(0, L_start - L_end)`` per task.

Committed rounds are immutable, so a run reads each one once (``load_round``, straight from the
dataset's parquet files) and keeps it in memory; a phase joins them (``TrainingData.concat``: the
vectors concatenated, the images and point clouds left in their rounds as ``FrameParts``, so the
largest inputs are held once) and normalises the frames with LeRobot's own pre-processor built from
their statistics, the same processor that is saved with the checkpoint; so what we train, what we
roll out and what ``lerobot-eval`` loads agree.

The training loop is lean: tasks are indices mapped once, the loss is the policy's
``imitation_loss`` and the loss history stays on the device until a log interval.
"""

from __future__ import annotations

import importlib.metadata
import io
import json
import logging
import math
import platform
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from tqdm import tqdm

from lerobot_mtdagger.datasets.records import PhaseRecord
from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy, make_mtdagger_pre_post_processors
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import per_task_means
from lerobot_mtdagger.policies.task_conditioning import TASK_FEATURE
from lerobot_mtdagger.runner.configs import UNSEEN_TASK_DROPOUT, PolicyOptions, RunConfig
from lerobot_mtdagger.runner.evaluate import PolicyRunner
from lerobot_mtdagger.runner.frame_parts import FrameParts, FrameTensor, join_frames, materialise
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.lerobot_compat import dataset_to_policy_features
from lerobot_mtdagger.utils.sampling import systematic_picks
from lerobot_mtdagger.utils.seeds import HELDOUT_STREAM, TRAINING_STREAM, stream_seed

logger = logging.getLogger(__name__)

LOSS_SAMPLES_PER_TASK = 1024

STATS_CHUNK = 8192
"""Frames read at a time for the normalisation statistics."""

MEASURE_CHUNK = 4096
"""Frames per forward pass when measuring per-task losses on vector inputs."""

MEASURE_CHUNK_VISUAL = 256
"""The same with an image or point-cloud input: 4 096 frames of 84 px RGB made about 3 GB of float
images and convolution activations at once (the pixel run's peak memory)."""

LOG_INTERVAL = 100
"""Steps between two syncs of the training loss (finiteness check, progress callback, debug log)."""

FINAL_LOSSES = 10
"""Step losses kept in ``PhaseResult.train_loss`` (the last ones of the phase)."""

EPISODE_ID_STRIDE = 1_000_000
"""``episode_id = episode_index + round_position * EPISODE_ID_STRIDE``."""


@dataclass
class TrainingData:
    """Frames of several rounds in memory.

    Attributes:
        inputs: Observation tensors by feature key; images stay uint8 (N, H, W, 3), the rest float32.
            Images and point clouds of several rounds are ``FrameParts`` (indexed like one tensor).
        action: Expert labels, (N, action_dim) float32.
        task_index: (N,) int64.
        episode_id: (N,) int64, unique per (round, episode).
    """

    inputs: dict[str, FrameTensor]
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

    @staticmethod
    def concat(parts: Sequence[TrainingData]) -> TrainingData:
        """The frames of ``parts`` one after the other (e.g. rounds loaded once and kept in memory).

        Vectors (one row per frame) are concatenated; inputs with more dimensions (images, point
        clouds) are joined without a copy (``join_frames``): a phase holds its rounds' images once.

        Raises:
            ValueError: If ``parts`` is empty or the parts hold different input keys.
        """
        if not parts:
            raise ValueError("TrainingData.concat needs at least one part.")
        keys = list(parts[0].inputs)
        for part in parts[1:]:
            if set(part.inputs) != set(keys):
                raise ValueError(f"Cannot concatenate inputs {sorted(part.inputs)} with {sorted(keys)}.")
        return TrainingData(
            inputs={k: _join_input([p.inputs[k] for p in parts]) for k in keys},
            action=torch.cat([p.action for p in parts]),
            task_index=torch.cat([p.task_index for p in parts]),
            episode_id=torch.cat([p.episode_id for p in parts]),
        )


def _join_input(tensors: Sequence[FrameTensor]) -> FrameTensor:
    """One input of several parts: vectors concatenated, images and point clouds as ``FrameParts``."""
    return torch.cat(tensors) if len(tensors[0].shape) <= 2 else join_frames(tensors)


def load_round(root: Path, round_position: int, input_keys: Sequence[str]) -> TrainingData:
    """Loads one committed round dataset into memory, straight from its parquet files.

    A LeRobot v3.0 dataset keeps its frames in ``<root>/data/chunk-XXX/file-YYY.parquet``; they are read
    with pyarrow in the order ``LeRobotDataset`` reads them (sorted paths), which skips building the
    dataset object and its Arrow cache. Image features (structs of PNG bytes) are decoded with PIL, as
    ``datasets`` does.

    Args:
        root: The round dataset folder.
        round_position: Position of the round among those trained on; offsets the episode ids so they
            stay unique across rounds.
        input_keys: Observation keys the policy reads.

    Returns:
        The round's frames.

    Raises:
        FileNotFoundError: If the folder holds no parquet file.
        KeyError: If an input key is not a feature of the dataset.
        ValueError: If an input is stored as a video (round datasets never are).
    """
    root = Path(root)
    features = json.loads((root / "meta" / "info.json").read_text())["features"]
    missing = [key for key in [*input_keys, "action"] if key not in features]
    if missing:
        raise KeyError(f"Round dataset {root} has no feature(s) {missing}; it has {sorted(features)}.")
    paths = sorted((root / "data").glob("*/*.parquet"))
    if not paths:
        raise FileNotFoundError(f"Round dataset {root} has no parquet file under data/.")
    columns = list(dict.fromkeys([*input_keys, "action", "task_index", "episode_index"]))
    table = pa.concat_tables([pq.read_table(path, columns=columns) for path in paths])
    inputs = {}
    for key in input_keys:
        dtype = features[key]["dtype"]
        if dtype == "image":
            inputs[key] = torch.from_numpy(_decode_images(table.column(key), root))
        elif dtype == "video":
            raise ValueError(f"Input {key!r} of {root} is a video; round datasets store images.")
        else:
            inputs[key] = torch.from_numpy(_column_values(table.column(key), features[key]["shape"]))
    episode = _column_values(table.column("episode_index"), (), np.int64)
    return TrainingData(
        inputs=inputs,
        action=torch.from_numpy(_column_values(table.column("action"), features["action"]["shape"])),
        task_index=torch.from_numpy(_column_values(table.column("task_index"), (), np.int64)),
        episode_id=torch.from_numpy(episode + round_position * EPISODE_ID_STRIDE),
    )


def _column_values(column: pa.ChunkedArray, shape: Sequence[int], dtype: type = np.float32) -> np.ndarray:
    """A numeric column (scalars or nested fixed-size lists) as an (N, *shape) array of ``dtype``."""
    array = column.combine_chunks() if column.num_chunks != 1 else column.chunk(0)
    if isinstance(array, pa.ExtensionArray):  # datasets' ArrayXD types
        array = array.storage
    while (
        pa.types.is_list(array.type)
        or pa.types.is_large_list(array.type)
        or pa.types.is_fixed_size_list(array.type)
    ):
        array = array.flatten()
        if isinstance(array, pa.ExtensionArray):
            array = array.storage
    values = np.array(array.to_numpy(zero_copy_only=False), dtype=dtype)  # owned, writable
    return values.reshape(len(column), *shape)


def _decode_images(column: pa.ChunkedArray, root: Path) -> np.ndarray:
    """An image column (structs of encoded bytes and path) as uint8 (N, H, W, C)."""
    from PIL import Image

    images = []
    for item in column.to_pylist():
        source = io.BytesIO(item["bytes"]) if item.get("bytes") is not None else root / item["path"]
        with Image.open(source) as image:
            images.append(np.asarray(image, dtype=np.uint8))
    return np.stack(images)


def load_rounds(roots: Sequence[Path], input_keys: Sequence[str]) -> TrainingData:
    """Loads committed round datasets into memory (``load_round`` each, then ``TrainingData.concat``).

    Args:
        roots: Round dataset folders, in round order.
        input_keys: Observation keys the policy reads.

    Returns:
        The concatenated frames.
    """
    return TrainingData.concat([load_round(root, i, input_keys) for i, root in enumerate(roots)])


def compute_stats(
    data: TrainingData, image_keys: Sequence[str], index: torch.Tensor | None = None
) -> dict[str, dict[str, np.ndarray]]:
    """Mean/std/min/max of the vector inputs and the action (point clouds per channel).

    Args:
        data: The frames.
        image_keys: Inputs without statistics (never read, so never copied).
        index: The frames the statistics come from (None: all).
    """
    frames = torch.arange(len(data)) if index is None else index
    tensors = {k: v for k, v in data.inputs.items() if k not in image_keys} | {"action": data.action}
    return {key: channel_stats(tensor, frames) for key, tensor in tensors.items()}


def channel_stats(tensor: FrameTensor, frames: torch.Tensor) -> dict[str, np.ndarray]:
    """Mean/std/min/max over the last axis' channels of ``tensor[frames]``, in float64 then float32.

    Read STATS_CHUNK frames at a time in one pass, each chunk's mean and squared deviations merged
    into the running ones (Chan et al.'s pairwise update), so a phase's point clouds are never
    copied whole.
    """
    channels = tensor.shape[-1]
    count = 0
    mean = torch.zeros(channels, dtype=torch.float64)
    squares = torch.zeros(channels, dtype=torch.float64)
    low = torch.full((channels,), math.inf, dtype=torch.float64)
    high = torch.full((channels,), -math.inf, dtype=torch.float64)
    for chunk in torch.split(frames, STATS_CHUNK):
        block = materialise(tensor[chunk]).reshape(-1, channels).double()
        block_mean = block.mean(0)
        delta, total = block_mean - mean, count + len(block)
        squares += ((block - block_mean) ** 2).sum(0) + delta**2 * count * len(block) / total
        mean += delta * len(block) / total
        count = total
        low, high = torch.minimum(low, block.min(0).values), torch.maximum(high, block.max(0).values)
    return {
        "mean": mean.float().numpy(),
        "std": (squares / count).sqrt().float().numpy(),
        "min": low.float().numpy(),
        "max": high.float().numpy(),
    }


def policy_config(
    suite_features: dict[str, Any],
    task_names: Sequence[str],
    options: Any,
    device: str = "cpu",
    task_dropout: float = 0.0,
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
        pointnet_layer_norm=options.pointnet_layer_norm,
        pointcloud_embedding_dim=options.pointcloud_embedding_dim,
        task_embedding_dim=options.task_embedding_dim,
        task_dropout=task_dropout,
        push_to_hub=False,
    )


class NormalisedData:
    """Training frames normalised once with the policy's pre-processor; batches built on demand.

    Tasks are carried as indices into ``task_names`` (checked once here), never as strings per batch.
    """

    def __init__(
        self, data: TrainingData, preprocessor: Any, image_keys: Sequence[str], task_names: Sequence[str]
    ):
        """Normalises the vector inputs and the action of ``data``.

        Raises:
            ValueError: If a frame's task index is outside ``task_names``.
        """
        self.data = data
        self.image_keys = list(image_keys)
        self.task_names = list(task_names)
        if len(data) and (int(data.task_index.min()) < 0 or int(data.task_index.max()) >= len(task_names)):
            raise ValueError(
                f"Task indices {torch.unique(data.task_index).tolist()} fall outside the "
                f"{len(task_names)} tasks {self.task_names}."
            )
        vector = {k: v for k, v in data.inputs.items() if k not in self.image_keys} | {"action": data.action}
        self.preprocessor = preprocessor
        self.vector = normalise_inputs(preprocessor, vector)
        self.device = self.vector["action"].device
        self.task_index = data.task_index.to(self.device, dtype=torch.long)

    @property
    def measure_chunk(self) -> int:
        """Frames per forward pass of a loss measurement (fewer with images or point clouds)."""
        visual = any(len(tensor.shape) > 2 for tensor in self.data.inputs.values())
        return MEASURE_CHUNK_VISUAL if visual else MEASURE_CHUNK

    def normalise_actions(self, actions: torch.Tensor, index: torch.Tensor) -> torch.Tensor:
        """Unnormalised actions for the frames at ``index``, normalised like the labels."""
        vector = {k: v[index] for k, v in self.data.inputs.items() if k not in self.image_keys}
        return self.preprocessor({**vector, "action": actions.float()})["action"]

    def batch(self, index: torch.Tensor) -> dict[str, torch.Tensor]:
        """The normalised batch at ``index``.

        Returns:
            The vectors, the images as float CHW in [0, 1] and ``task_index`` (indices into
            ``task_names``), all on the data's device.
        """
        index = index.to(self.device)
        batch = {k: v[index] for k, v in self.vector.items()}
        for key in self.image_keys:
            images = self.data.inputs[key][index.cpu()].to(self.device)
            batch[key] = images.permute(0, 3, 1, 2).float() / 255.0
        batch["task_index"] = self.task_index[index]
        return batch


def normalise_inputs(preprocessor: Any, vector: dict[str, FrameTensor]) -> dict[str, FrameTensor]:
    """``vector`` through the pre-processor: tensors at once, ``FrameParts`` part by part (never joined).

    Args:
        preprocessor: The policy's pre-processor (normalisation of each key is per feature, so parts
            normalise as the whole would).
        vector: The action and the non-image inputs by key.
    """
    whole = {k: v for k, v in vector.items() if not isinstance(v, FrameParts)}
    normalised = preprocessor(dict(whole))
    result: dict[str, FrameTensor] = {k: normalised[k] for k in whole}
    for key, parts in vector.items():
        if isinstance(parts, FrameParts):
            result[key] = parts.map(lambda part, key=key: preprocessor({key: part})[key])
    return result


@dataclass
class PhaseResult:
    """Per-task losses of one training phase (lists aligned with the task names; None: no sample).

    Attributes:
        loss_start: Per-task loss before training.
        loss_end: Per-task loss of the returned weights.
        gain: ``max(0, loss_start - loss_end)`` per task.
        train_loss: The last FINAL_LOSSES step losses.
        loss_samples: Frames per task behind the losses.
        steps: Optimiser steps taken (fewer than asked where a plateau stopped the phase).
        best_step: With a plateau stop, the step whose weights are returned (0: the initial ones).
        heldout_loss: With a plateau stop, ``[step, mean held-out loss]`` at every measurement.
        steps_s: Seconds spent in the optimiser steps (the bare training).
        task_loss_s: Seconds spent measuring the per-task loss before and after them.
        passes_per_task: Per task, the frames its steps drew divided by its training frames: how
            many times over its data the phase went (None where a task had no training frame).
    """

    loss_start: list[float | None]
    loss_end: list[float | None]
    gain: list[float]
    train_loss: list[float]
    loss_samples: list[int]
    steps: int = 0
    best_step: int | None = None
    heldout_loss: list[list[float]] | None = None
    steps_s: float = field(default=0.0, compare=False)  # timings: equal phases differ in them
    task_loss_s: float = field(default=0.0, compare=False)
    passes_per_task: list[float | None] | None = None


@dataclass(frozen=True)
class FrameSplit:
    """Which frames a phase trains on, measures the per-task loss on, and holds out.

    Attributes:
        train: Frames to train on.
        loss: Frames the per-task loss (performance gain) is measured on.
        heldout: Frames of the held-out episodes (empty when nothing is held out).
    """

    train: torch.Tensor
    loss: torch.Tensor
    heldout: torch.Tensor


def split_frames(
    data: TrainingData, gain_split: str, heldout_fraction: float, seed: int, hold_out: bool = False
) -> FrameSplit:
    """Splits the frames of D(k) into training, loss-measurement and held-out frames.

    Episodes are held out (``heldout_episodes``) when ``gain_split == "heldout"`` or ``hold_out`` (a
    plateau stop needs them); they are never trained on. The per-task loss is measured on them with
    ``gain_split == "heldout"``, else on up to LOSS_SAMPLES_PER_TASK training frames per task. The
    choice depends only on ``seed`` and the episodes, so an episode held out in one phase is held out
    in every later phase (pass the experiment's seed, not a per-phase one): a warm-started policy never
    trained on it.
    """
    all_index = torch.arange(len(data))
    held = torch.zeros(len(data), dtype=torch.bool)
    if gain_split == "heldout" or hold_out:
        held_ids = heldout_episodes(data, heldout_fraction, seed)
        held = torch.from_numpy(np.isin(data.episode_id.numpy(), held_ids))
    train_index, heldout_index = all_index[~held], all_index[held]
    if gain_split == "heldout":
        return FrameSplit(train=train_index, loss=heldout_index, heldout=heldout_index)
    generator = np.random.default_rng(seed)
    measure = []
    for task in torch.unique(data.task_index[train_index]).tolist():
        task_frames = train_index[data.task_index[train_index] == task].numpy()
        size = min(LOSS_SAMPLES_PER_TASK, len(task_frames))
        measure.append(np.sort(generator.choice(task_frames, size=size, replace=False)))
    loss_index = torch.from_numpy(np.concatenate(measure))
    return FrameSplit(train=train_index, loss=loss_index, heldout=heldout_index)


def heldout_episodes(data: TrainingData, heldout_fraction: float, seed: int) -> list[int]:
    """Episode ids held out: systematic sampling over each task's episodes in round order.

    A task's episodes are taken in id order (round, then episode). Its first one is always trained on
    (a task never loses all its frames); of the others, the one at position ``j`` (0-based) is held
    out when ``floor(f * (j + 1) + u)`` steps up at ``j``, with one uniform offset ``u`` per
    (seed, task). So a task's first ``n`` episodes hold ``floor(f (n - 1))`` or ``ceil(f (n - 1))``
    held-out ones however they are split into rounds (BC's one round and DAgger's many hold out the
    same share), and a new round never moves an earlier episode to the other side.
    """
    episode_ids = data.episode_id.numpy()
    task_index = data.task_index.numpy()
    chosen: list[int] = []
    for task in np.unique(task_index).tolist():
        episodes = np.unique(episode_ids[task_index == task])  # sorted: round order, then episode
        chosen += episodes[heldout_mask(len(episodes), heldout_fraction, seed, task)].tolist()
    return chosen


def heldout_mask(count: int, heldout_fraction: float, seed: int, task: int) -> np.ndarray:
    """Which of a task's first ``count`` episodes (in round order) are held out (``heldout_episodes``)."""
    offset = float(np.random.default_rng(np.random.SeedSequence([seed, HELDOUT_STREAM, task])).random())
    later = systematic_picks(heldout_fraction, max(count - 1, 0), offset)  # the episodes after the first
    return np.concatenate([np.zeros(min(count, 1), dtype=bool), later])


@torch.no_grad()
def per_task_loss(
    policy: MTDAggerPolicy, data: NormalisedData, index: torch.Tensor, num_tasks: int
) -> tuple[list, list]:
    """Mean MSE per task over the frames at ``index`` (None where a task has none) and the counts."""
    policy.eval()
    sums = torch.zeros(num_tasks, dtype=torch.float64, device=data.device)
    counts = torch.zeros(num_tasks, dtype=torch.float64, device=data.device)
    for chunk in torch.split(index, data.measure_chunk):
        batch = data.batch(chunk)
        prediction = policy.predict(batch, task_index=batch["task_index"])
        errors = ((prediction - batch["action"]) ** 2).mean(dim=1).double()
        means, chunk_counts = per_task_means(errors, batch["task_index"], num_tasks)
        sums += means * chunk_counts
        counts += chunk_counts
    sums, counts = sums.cpu(), counts.cpu()
    losses = [float(sums[i] / counts[i]) if counts[i] > 0 else None for i in range(num_tasks)]
    return losses, [int(c) for c in counts.tolist()]


@torch.no_grad()
def per_task_loss_of(
    predict: Callable[[dict[str, torch.Tensor], list[str]], torch.Tensor],
    data: NormalisedData,
    index: torch.Tensor,
    num_tasks: int,
) -> list[float | None]:
    """Mean MSE per task of another policy's actions, in ``data``'s normalisation.

    The other policy (e.g. the previous phase's, with its own normalisation statistics) acts on the
    raw frames; its unnormalised actions are normalised like ``data``'s labels, so its loss is
    comparable with ``per_task_loss`` of the policy trained on ``data``.

    Args:
        predict: Raw inputs by key and task names -> unnormalised actions (``PolicyRunner.predict``).
        data: The normalised frames (its pre-processor normalises the predictions).
        index: Frames to measure on.
        num_tasks: Number of tasks.

    Returns:
        The loss per task (None where a task has no frame at ``index``).
    """
    sums = torch.zeros(num_tasks, dtype=torch.float64)
    counts = torch.zeros(num_tasks, dtype=torch.float64)
    for chunk in torch.split(index, data.measure_chunk):
        inputs = {key: tensor[chunk] for key, tensor in data.data.inputs.items()}
        task_index = data.data.task_index[chunk]
        raw = predict(inputs, [data.task_names[i] for i in task_index.tolist()])
        prediction = data.normalise_actions(raw, chunk).cpu()
        errors = ((prediction - data.vector["action"][chunk.to(data.device)].cpu()) ** 2).mean(dim=1).double()
        means, chunk_counts = per_task_means(errors, task_index, num_tasks)
        sums += means * chunk_counts
        counts += chunk_counts
    return [float(sums[i] / counts[i]) if counts[i] > 0 else None for i in range(num_tasks)]


def make_optimizer(policy: MTDAggerPolicy, lr: float) -> torch.optim.AdamW:
    """AdamW over the policy's parameters with its configured weight decay.

    The update is one fused kernel per step on CPU and CUDA rather than a Python loop over tensors.
    """
    fused = policy.task_embedding.weight.device.type in ("cpu", "cuda")
    return torch.optim.AdamW(
        policy.parameters(),
        lr=lr,
        weight_decay=policy.config.optimizer_weight_decay,
        fused=fused or None,
    )


class MTDAggerOps:
    """The training seam for the ``mtdagger`` policy (``students.LeRobotOps`` for LeRobot's).

    A step's loss is ``policy.imitation_loss`` (the first step of each log interval calls the full
    ``policy.forward``: same loss and gradient, with per-task losses logged at debug level); the
    per-task loss is the action MSE of ``policy.predict``; the optimiser is a fused AdamW.
    """

    def __init__(
        self, policy: MTDAggerPolicy, data: NormalisedData, lr: float, lr_schedule: str = "constant"
    ) -> None:
        """Remembers the policy, its frames, the learning rate and its schedule over a phase."""
        self.policy = policy
        self.data = data
        self.lr = lr
        self.lr_schedule = lr_schedule

    def step_loss(self, index: torch.Tensor, first_of_interval: bool) -> torch.Tensor:
        """The imitation loss on the frames at ``index``."""
        batch = self.data.batch(index)
        if not first_of_interval:
            return self.policy.imitation_loss(batch, task_index=batch["task_index"])
        loss, info = self.policy.forward(batch)
        info = info or {}
        logger.debug("loss %s, per task %s", info.get("loss"), info.get("per_task_loss"))
        return loss

    def task_losses(self, index: torch.Tensor, num_tasks: int) -> tuple[list, list]:
        """Mean action MSE per task (``per_task_loss``)."""
        return per_task_loss(self.policy, self.data, index, num_tasks)

    def optimizer(self, steps: int) -> tuple[torch.optim.Optimizer, Any, float]:
        """Fused AdamW (``make_optimizer``), its schedule over ``steps``, the config's gradient clip norm.

        ``constant``: no scheduler; ``cosine``: the rate decays from ``lr`` to 0 at step ``steps``.
        """
        optimizer = make_optimizer(self.policy, self.lr)
        scheduler = None
        if self.lr_schedule == "cosine":
            scheduler = torch.optim.lr_scheduler.CosineAnnealingLR(optimizer, T_max=max(steps, 1))
        return optimizer, scheduler, self.policy.config.optimizer_grad_clip_norm


def phase_ops(policy: Any, data: NormalisedData, options: StepOptions) -> Any:
    """The training seam of ``policy``: ``MTDAggerOps`` or ``students.LeRobotOps``."""
    if isinstance(policy, MTDAggerPolicy):
        return MTDAggerOps(policy, data, options.lr, options.lr_schedule)
    from lerobot_mtdagger.runner.students import LeRobotOps

    return LeRobotOps(policy, data, options.task_dropout, options.seed)


@dataclass(frozen=True)
class PlateauStop:
    """Ends a phase when the loss on held-out frames stops improving (``steps_rule=plateau``).

    The mean over tasks of the per-task loss on ``index`` is measured before the first step and every
    ``every`` steps; the phase ends after ``patience`` measurements in a row without a new minimum (or
    at the step cap) and returns the weights of the minimum.

    Attributes:
        index: The held-out frames (never trained on).
        every: Steps between two measurements.
        patience: Measurements without a new minimum before the phase ends.
    """

    index: torch.Tensor
    every: int
    patience: int


class _PlateauTracker:
    """The held-out loss curve of a phase and the weights of its minimum."""

    def __init__(self, stop: PlateauStop, ops: Any, data: NormalisedData):
        self.stop = stop
        self.ops = ops
        self.policy = ops.policy
        self.data = data
        self.curve: list[list[float]] = []
        self.best_loss = math.inf
        self.best_step = 0
        self.best_state: dict[str, torch.Tensor] = {}
        self.since_best = 0

    def measure(self, step: int) -> bool:
        """Measures the held-out loss after ``step`` steps; True when the phase should end."""
        losses, _ = self.ops.task_losses(self.stop.index, len(self.data.task_names))
        self.policy.train()
        measured = [loss for loss in losses if loss is not None]
        mean = float(np.mean(measured))
        self.curve.append([step, mean])
        if mean < self.best_loss:
            self.best_loss, self.best_step, self.since_best = mean, step, 0
            self.best_state = {k: v.detach().clone() for k, v in self.policy.state_dict().items()}
            return False
        self.since_best += 1
        return self.since_best >= self.stop.patience

    def restore_best(self) -> None:
        """Loads the weights of the lowest held-out loss into the policy."""
        self.policy.load_state_dict(self.best_state)


class _LossWindow:
    """Step losses kept on the device and read back once per log interval."""

    def __init__(self, on_step: Callable[[int, float], None] | None):
        self.on_step = on_step
        self.window: list[torch.Tensor] = []
        self.tail = torch.empty(0)  # the last FINAL_LOSSES step losses, on the CPU

    def add(self, loss: torch.Tensor) -> None:
        """Keeps one step's loss (no sync)."""
        self.window.append(loss.detach())

    def flush(self, steps_done: int) -> None:
        """Reads the pending losses back, checks them and reports progress."""
        if not self.window:
            return
        losses = torch.stack(self.window).float().cpu()  # the one sync of the interval
        _check_finite(losses, steps_done - len(self.window))
        self.window = []
        self.tail = torch.cat([self.tail, losses])[-FINAL_LOSSES:]
        if self.on_step is not None:
            self.on_step(steps_done, float(losses.double().mean()))


@dataclass(frozen=True)
class StepOptions:
    """How a training phase steps.

    Attributes:
        steps: Optimiser steps (the cap, with ``plateau``).
        batch_size: Frames per step (capped at the number of training frames).
        lr: AdamW learning rate.
        seed: Seed of the batch sampling.
        sampling: ``uniform`` over frames or ``balanced`` over tasks.
        lr_schedule: ``constant`` or ``cosine`` over ``steps`` (``mtdagger``; a LeRobot student
            follows its config's scheduler preset).
        plateau: End the phase when the held-out loss stops improving and keep the weights of its
            minimum (None: train all ``steps``).
        log_interval: Steps between two reads of the loss.
        task_dropout: A LeRobot student's task dropout (``mtdagger``'s is in its config).
    """

    steps: int
    batch_size: int
    lr: float
    seed: int
    sampling: str = "uniform"
    lr_schedule: str = "constant"
    plateau: PlateauStop | None = None
    log_interval: int = LOG_INTERVAL
    task_dropout: float = 0.0


def train_phase(
    policy: MTDAggerPolicy,
    data: NormalisedData,
    train_index: torch.Tensor,
    loss_index: torch.Tensor,
    options: StepOptions,
    on_step: Callable[[int, float], None] | None = None,
) -> PhaseResult:
    """Trains ``policy`` for ``options.steps`` steps (or until a plateau); measures the per-task loss drop.

    Each step samples ``batch_size`` frames of ``train_index`` with replacement (uniformly, or with
    ``sampling="balanced"`` a task uniformly and then one of its frames uniformly) and takes
    one optimiser step on the student's loss through its seam (``phase_ops``): for ``mtdagger`` an
    AdamW step on ``policy.imitation_loss`` with the gradient norm clipped to
    ``config.optimizer_grad_clip_norm`` (the first step of each interval calls the full
    ``policy.forward``, same loss and gradient, and logs its per-task losses at debug level); for a
    LeRobot student its ``forward`` loss with its config's optimiser and scheduler presets. The losses
    stay on the device: they are read back only every ``log_interval`` steps and after the last one,
    where they are checked for NaN/inf and reported. The result depends only on the inputs and
    ``seed`` (not on ``log_interval``).

    Args:
        policy: The policy to train, in place: ``mtdagger`` (its ``task_names`` must be
            ``data.task_names``) or a LeRobot student reading a one-hot vector over them.
        data: The normalised frames.
        train_index: Frames to train on.
        loss_index: Frames the per-task loss is measured on, before and after.
        options: Steps, batch size, learning rate, sampling seed and rule, plateau stop.
        on_step: Progress callback, called every ``log_interval`` steps and after the last step as
            ``on_step(steps_done, mean_loss)``: the number of steps completed so far (1..steps) and the
            mean training loss over the steps since the previous call.

    Returns:
        The per-task losses at the start and at the end, the gain, the last FINAL_LOSSES step
        losses and the steps taken (with ``plateau``, the held-out curve and the step kept).

    Raises:
        ValueError: If the policy's task vocabulary differs from the data's, log_interval < 1,
            ``sampling`` is unknown or ``plateau`` has no held-out frame.
        FloatingPointError: If the loss becomes NaN or infinite (nothing is committed then).
    """
    steps, log_interval, plateau = options.steps, options.log_interval, options.plateau
    _check_phase_inputs(policy, data, log_interval, plateau)
    num_tasks = len(data.task_names)
    ops = phase_ops(policy, data, options)
    started = time.perf_counter()
    loss_start, _ = ops.task_losses(loss_index, num_tasks)
    measured = time.perf_counter()
    generator = torch.Generator().manual_seed(options.seed)
    draw = batch_sampler(train_index, data.data.task_index, options.sampling, generator)
    optimizer, scheduler, clip_norm = ops.optimizer(steps)
    parameters = [p for p in policy.parameters() if p.requires_grad]
    size = min(options.batch_size, len(train_index))
    tracker = None if plateau is None else _PlateauTracker(plateau, ops, data)
    stopped = tracker is not None and tracker.measure(0)
    policy.train()
    losses = _LossWindow(on_step)
    picks = torch.empty(0, dtype=torch.long)
    draws = DrawCounter(data.data.task_index, train_index, num_tasks)
    done = 0
    while done < steps and not stopped:
        offset = done % log_interval
        if offset == 0:
            # One interval's batch indices at once, drawn on the CPU (device independent).
            drawn = draw((min(log_interval, steps - done), size))
            draws.start_interval(drawn)
            picks = drawn.to(data.device)
        draws.count(offset)
        loss = ops.step_loss(picks[offset], first_of_interval=offset == 0)
        if offset == 0:
            _check_finite(loss.detach().reshape(1), done)
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(parameters, clip_norm, foreach=True)
        optimizer.step()
        if scheduler is not None:
            scheduler.step()
        losses.add(loss)
        done += 1
        if offset == log_interval - 1 or done == steps:
            losses.flush(done)
        if tracker is not None and (done % tracker.stop.every == 0 or done == steps):
            losses.flush(done)
            stopped = tracker.measure(done)
    if tracker is not None:
        tracker.restore_best()
    trained = time.perf_counter()
    loss_end, counts = ops.task_losses(loss_index, num_tasks)
    return PhaseResult(
        loss_start=loss_start,
        loss_end=loss_end,
        gain=performance_gain(loss_start, loss_end),
        train_loss=losses.tail.tolist(),
        loss_samples=counts,
        steps=done,
        best_step=None if tracker is None else tracker.best_step,
        heldout_loss=None if tracker is None else tracker.curve,
        steps_s=trained - measured,
        task_loss_s=(measured - started) + (time.perf_counter() - trained),
        passes_per_task=draws.passes(),
    )


def _check_phase_inputs(
    policy: Any, data: NormalisedData, log_interval: int, plateau: PlateauStop | None
) -> None:
    """Refuses a policy of other tasks, a log interval < 1 and a plateau stop without held-out frames."""
    task_names = getattr(policy.config, "task_names", None)
    if task_names is not None and list(task_names) != data.task_names:
        raise UserError(f"The policy's tasks {task_names} differ from the data's {data.task_names}.")
    task_vector = policy.config.input_features.get(TASK_FEATURE)
    if task_names is None and (task_vector is None or task_vector.shape != (len(data.task_names),)):
        raise UserError(
            f"The policy reads no one-hot task vector over the data's {len(data.task_names)} tasks "
            f"({TASK_FEATURE}: {task_vector}); build it with students.lerobot_student_config."
        )
    if log_interval < 1:
        raise ValueError(f"log_interval must be >= 1, got {log_interval}.")
    if plateau is not None and (len(plateau.index) == 0 or plateau.every < 1 or plateau.patience < 1):
        raise ValueError(
            f"A plateau stop needs held-out frames, every >= 1 and patience >= 1; got "
            f"{len(plateau.index)} frames, every={plateau.every}, patience={plateau.patience}."
        )


class DrawCounter:
    """Counts the frames each task's steps drew, for ``PhaseResult.passes_per_task``."""

    def __init__(self, task_index: torch.Tensor, train_index: torch.Tensor, num_tasks: int) -> None:
        """Starts at zero draws; ``train_index``'s frames per task are the denominators."""
        self.task_index = task_index.cpu()
        self.frames = torch.bincount(self.task_index[train_index.cpu()], minlength=num_tasks)
        self.drawn = torch.zeros(num_tasks, dtype=torch.long)
        self.tasks = torch.empty(0, dtype=torch.long)

    def start_interval(self, picks: torch.Tensor) -> None:
        """An interval's drawn frames ``(steps, batch)``, on the CPU."""
        self.tasks = self.task_index[picks]

    def count(self, offset: int) -> None:
        """Counts the draws of the interval's step ``offset`` (the steps taken, not those drawn ahead)."""
        self.drawn += torch.bincount(self.tasks[offset], minlength=len(self.drawn))

    def passes(self) -> list[float | None]:
        """Draws over training frames, per task."""
        return [float(d) / float(f) if f > 0 else None for d, f in zip(self.drawn, self.frames, strict=True)]


def batch_sampler(
    train_index: torch.Tensor, task_index: torch.Tensor, sampling: str, generator: torch.Generator
) -> Callable[[tuple[int, int]], torch.Tensor]:
    """A function drawing frame indices of ``train_index`` in a given shape, with replacement.

    ``uniform``: every frame equally likely. ``balanced``: a task uniformly among those with
    training frames, then one of its frames uniformly (each task gets the same share of every batch
    in expectation, however many frames it has).

    Raises:
        ValueError: If ``sampling`` is unknown.
    """
    if sampling == "uniform":
        return lambda shape: train_index[torch.randint(len(train_index), shape, generator=generator)]
    if sampling != "balanced":
        raise ValueError(f"sampling must be 'uniform' or 'balanced', got {sampling!r}.")
    tasks_of_frames = task_index[train_index]
    order = torch.argsort(tasks_of_frames, stable=True)
    grouped = train_index[order]
    _, counts = torch.unique_consecutive(tasks_of_frames[order], return_counts=True)
    starts = torch.cumsum(counts, 0) - counts

    def draw(shape: tuple[int, int]) -> torch.Tensor:
        task = torch.randint(len(counts), shape, generator=generator)
        within = (torch.rand(shape, generator=generator) * counts[task]).long()
        return grouped[starts[task] + torch.minimum(within, counts[task] - 1)]

    return draw


def performance_gain(loss_before: list[float | None], loss_after: list[float | None]) -> list[float]:
    """``max(0, L_before - L_after)`` per task (0 where a task has no measured loss)."""
    return [
        max(0.0, before - after) if before is not None and after is not None else 0.0
        for before, after in zip(loss_before, loss_after, strict=True)
    ]


def _check_finite(losses: torch.Tensor, first_step: int) -> None:
    """Raises FloatingPointError at the first NaN/inf of ``losses`` (step ``first_step`` onwards)."""
    finite = torch.isfinite(losses)
    if not bool(finite.all()):
        bad = int(torch.nonzero(~finite)[0, 0])
        raise FloatingPointError(
            f"Training loss became {float(losses[bad])} at step {first_step + bad}; nothing was committed."
        )


def save_policy(policy: MTDAggerPolicy, preprocessor: Any, postprocessor: Any, folder: Path) -> None:
    """Writes a LeRobot pretrained model folder (config, weights, processors)."""
    policy.save_pretrained(folder)
    preprocessor.save_pretrained(folder)
    postprocessor.save_pretrained(folder)


def build_processors(config: MTDAggerConfig, stats: dict[str, dict[str, np.ndarray]]) -> tuple[Any, Any]:
    """The policy's LeRobot pre- and post-processors for ``stats``."""
    return make_mtdagger_pre_post_processors(config, dataset_stats=stats)


# -------------------------------------------------------------------------------------------------
# A run's training phase: D(k) in, a trained student and its per-task losses out
# -------------------------------------------------------------------------------------------------


class RoundCache:
    """Committed rounds read once per run and kept in memory (committed rounds never change)."""

    def __init__(self) -> None:
        self.rounds: list[TrainingData] = []

    def load(self, roots: Sequence[Path], input_keys: Sequence[str]) -> TrainingData:
        """D(k) for the round folders ``roots`` (rounds 0..k in order); only new rounds are read."""
        for position in range(len(self.rounds), len(roots)):
            self.rounds.append(load_round(roots[position], position, input_keys))
        return TrainingData.concat(self.rounds[: len(roots)])


def student_config(
    config: RunConfig, features: dict[str, Any], task_names: Sequence[str], unseen: bool
) -> Any:
    """The student's policy config for a run on a suite's ``features`` (``unseen``: it has held-out tasks).

    An ``MTDAggerConfig`` for ``--policy.type=mtdagger``, else a ``students.LeRobotStudentConfig``
    (task dropout ``UNSEEN_TASK_DROPOUT`` on a suite with held-out tasks, else 0).
    """
    if isinstance(config.policy, PolicyOptions):
        task_dropout = config.policy.resolved_task_dropout(unseen)
        return policy_config(features, task_names, config.policy, config.policy.device, task_dropout)
    from lerobot_mtdagger.runner.students import lerobot_student_config

    return lerobot_student_config(config.policy, features, task_names, UNSEEN_TASK_DROPOUT if unseen else 0.0)


def _new_student(policy_cfg: Any, stats: dict[str, dict[str, np.ndarray]]) -> tuple[Any, Any, Any]:
    """A freshly initialised student on its config's device, and its processors for ``stats``.

    The weights are drawn on the CPU and then moved, so a seed gives the same initial weights on
    every device (LeRobot's policy constructors leave a policy on the CPU; its ``make_policy`` moves it).
    """
    if isinstance(policy_cfg, MTDAggerConfig):
        return MTDAggerPolicy(policy_cfg).to(policy_cfg.device), *build_processors(policy_cfg, stats)
    from lerobot_mtdagger.runner.students import make_lerobot_processors, make_lerobot_student

    return make_lerobot_student(policy_cfg), *make_lerobot_processors(policy_cfg, stats)


def _previous_losses(
    runner: PolicyRunner, normalised: NormalisedData, index: torch.Tensor, options: StepOptions
) -> list[float | None]:
    """The previous phase's policy's per-task loss on this phase's loss frames (performance gain's start).

    ``mtdagger``: the MSE of its actions (through its own processors) in this phase's normalisation;
    a LeRobot student: its own training loss on this phase's normalised frames.
    """
    num_tasks = len(normalised.task_names)
    if isinstance(runner.policy, MTDAggerPolicy):
        return per_task_loss_of(runner.predict, normalised, index, num_tasks)
    return phase_ops(runner.policy, normalised, options).task_losses(index, num_tasks)[0]


@dataclass
class TrainedPhase:
    """A trained student with its processors and what its phase measured.

    Attributes:
        policy: The trained policy (its weights are the phase's result).
        preprocessor: Its LeRobot pre-processor (normalisation statistics of the phase's frames).
        postprocessor: Its post-processor.
        result: The per-task losses and steps of the phase.
        loss_previous: The previous phase's policy's per-task loss on this phase's loss frames (None
            in round 0): the loss performance gain is measured from.
        frames: Frames of D(k).
        prepare_s: Seconds spent before the first step (statistics, previous policy, its losses).
        train_s: Seconds spent training.
    """

    policy: MTDAggerPolicy
    preprocessor: Any
    postprocessor: Any
    result: PhaseResult
    loss_previous: list[float | None] | None
    frames: int
    prepare_s: float
    train_s: float

    @property
    def gain(self) -> list[float] | None:
        """Performance gain per task against the previous phase's policy (None in round 0)."""
        if self.loss_previous is None:
            return None
        return performance_gain(self.loss_previous, self.result.loss_end)

    def save(self, folder: Path) -> None:
        """Writes the LeRobot pretrained model folder."""
        save_policy(self.policy, self.preprocessor, self.postprocessor, folder)

    def record(
        self, round_index: int, gain_split: str, demos: list[int], timings: dict[str, float]
    ) -> PhaseRecord:
        """The phase's record without its evaluations (``eval`` and ``heldout_eval`` are None)."""
        result = self.result
        return PhaseRecord(
            round=round_index,
            trained_on_rounds=list(range(round_index + 1)),
            frames=self.frames,
            steps=result.steps,
            gain_split=gain_split,
            loss_start=result.loss_start,
            loss_end=result.loss_end,
            gain=self.gain,
            loss_previous=self.loss_previous,
            loss_samples=result.loss_samples,
            final_train_loss=result.train_loss,
            eval=None,
            heldout_eval=None,
            demos_per_task=demos,
            timings=timings,
            best_step=result.best_step,
            heldout_loss=result.heldout_loss,
            environment=training_environment(next(self.policy.parameters()).device),
            passes_per_task=result.passes_per_task,
        )


ENVIRONMENT_PACKAGES = ("torch", "numpy", "lerobot", "mujoco", "metaworld", "lerobot-mtdagger")
"""The packages whose versions a phase records (``PhaseRecord.environment``)."""


def training_environment(device: torch.device) -> dict[str, Any]:
    """Where a phase trains: what decides its arithmetic, so two trainings can be told apart later.

    Args:
        device: The device the policy trained on.

    Returns:
        Package versions (None for one not installed), the CPU, torch's CPU kernel level, torch's
        thread count, the device (and its name on CUDA) and the Python version.
    """
    versions = {}
    for name in ENVIRONMENT_PACKAGES:
        try:
            versions[name] = importlib.metadata.version(name)
        except importlib.metadata.PackageNotFoundError:
            versions[name] = None
    return {
        "packages": versions,
        "python": platform.python_version(),
        "cpu": cpu_model(),
        "cpu_capability": torch.backends.cpu.get_cpu_capability(),
        "torch_threads": torch.get_num_threads(),
        "device": str(device),
        "device_name": torch.cuda.get_device_name(device) if device.type == "cuda" else None,
    }


def cpu_model() -> str:
    """The CPU's model name (Linux's ``/proc/cpuinfo``), else what ``platform`` knows."""
    cpuinfo = Path("/proc/cpuinfo")
    if cpuinfo.is_file():
        for line in cpuinfo.read_text(errors="replace").splitlines():
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    return platform.processor() or platform.machine()


def train_on_rounds(
    config: RunConfig,
    policy_cfg: Any,
    data: TrainingData,
    round_index: int,
    previous: Path | None,
    show_progress: bool = False,
) -> TrainedPhase:
    """Algorithm 1's "Train Policy" for round ``round_index`` of a run: trains a student on D(k).

    Splits the frames (``split_frames``), normalises them with statistics of the run's rule, builds
    the student (warm-started from ``previous`` when the run says so), measures the previous
    policy's per-task loss for performance gain and trains for the run's steps.

    Args:
        config: The run's config (training options, seed, split and step rules).
        policy_cfg: The student's config (``student_config``).
        data: D(k), the frames of rounds 0..k.
        round_index: k.
        previous: The folder of round k-1's policy (None in round 0).
        show_progress: Show a progress bar over the steps.
    """
    start = time.perf_counter()
    image_keys = list(policy_cfg.image_features)
    phase_seed = stream_seed(config.training_seed, TRAINING_STREAM, round_index)
    split = split_frames(
        data,
        config.training.gain_split,
        config.training.heldout_fraction,
        config.seed,
        hold_out=config.training.steps_rule == "plateau",
    )
    stats = compute_stats(data, image_keys, normalisation_frames(config, data, split.train))
    torch.manual_seed(phase_seed)
    policy, preprocessor, postprocessor = _new_student(policy_cfg, stats)
    runner = None if previous is None else PolicyRunner.from_pretrained(previous, config.policy.device)
    if runner is not None and config.training.warm_start:
        policy.load_state_dict(runner.policy.state_dict())
    normalised = NormalisedData(data, preprocessor, image_keys, list(policy_cfg.task_names))
    options = StepOptions(
        steps=config.phase_steps(len(split.train)),
        batch_size=config.policy.batch_size,
        lr=getattr(config.policy, "lr", None) or config.policy.optimizer_lr,
        seed=phase_seed,
        sampling=config.training.sampling,
        lr_schedule=config.training.lr_schedule,
        plateau=plateau_stop(config, split),
        task_dropout=getattr(policy_cfg, "task_dropout", 0.0),
    )
    loss_previous = None if runner is None else _previous_losses(runner, normalised, split.loss, options)
    prepared = time.perf_counter()
    with tqdm(
        total=options.steps, desc=f"round {round_index} train", leave=False, disable=not show_progress
    ) as bar:
        result = train_phase(
            policy,
            normalised,
            split.train,
            split.loss,
            options,
            on_step=lambda done, _: bar.update(done - bar.n),
        )
    return TrainedPhase(
        policy=policy,
        preprocessor=preprocessor,
        postprocessor=postprocessor,
        result=result,
        loss_previous=loss_previous,
        frames=len(data),
        prepare_s=prepared - start,
        train_s=time.perf_counter() - prepared,
    )


def plateau_stop(config: RunConfig, split: FrameSplit) -> PlateauStop | None:
    """The phase's plateau stop on the held-out frames (``steps_rule=plateau``), or None."""
    training = config.training
    if training.steps_rule != "plateau":
        return None
    return PlateauStop(index=split.heldout, every=training.plateau_every, patience=training.plateau_patience)


def normalisation_frames(config: RunConfig, data: TrainingData, train_index: torch.Tensor) -> torch.Tensor:
    """The training frames the normalisation statistics come from: round 0's (``fixed``) or all."""
    if config.training.normalisation == "recompute":
        return train_index
    return train_index[data.episode_id[train_index] < EPISODE_ID_STRIDE]


def check_heldout(config: RunConfig, num_tasks: int) -> None:
    """Refuses ``training.steps_rule=plateau`` when round 0 would hold no episode out, before anything runs.

    Raises:
        UserError: With the numbers and the fix.
    """
    training, demos = config.training, config.dagger.initial_demos
    if training.steps_rule != "plateau":
        return
    fraction = training.heldout_fraction
    if not any(heldout_mask(demos, fraction, config.seed, task).any() for task in range(num_tasks)):
        raise UserError(
            f"--training.steps_rule=plateau needs held-out episodes, and round 0 would hold none out: a "
            f"task's first episode is always trained on, and --training.heldout_fraction={fraction} of "
            f"the other {demos - 1} per task gives none. Raise --training.heldout_fraction or "
            "--dagger.initial_demos, or choose --training.steps_rule=fixed or epochs."
        )
