"""One training phase of the multitask policy, with the per-task losses that performance gain needs.

Algorithm 1, "Train Policy": train on D(k) (all committed rounds so far), recording each task's
imitation loss at the start and at the end of the phase, on the training data itself or on a held-out
split of episodes; the gain is ``max(0, L_start - L_end)`` per task.

Committed rounds are immutable, so a run reads each one once (``load_round``, straight from the
dataset's parquet files) and keeps it in memory; a phase concatenates them (``TrainingData.concat``)
and normalises the frames with LeRobot's own pre-processor built from their statistics, the same
processor that is saved with the checkpoint; so what we train, what we roll out and what
``lerobot-eval`` loads agree.

The training loop is lean: tasks are indices mapped once, the loss is the policy's
``imitation_loss`` and the loss history stays on the device until a log interval.
"""

from __future__ import annotations

import io
import json
import logging
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import torch
from lerobot.configs.types import FeatureType, PolicyFeature
from lerobot.datasets.utils import dataset_to_policy_features

from lerobot_mtdagger.errors import UserError
from lerobot_mtdagger.policies import MTDAggerConfig, MTDAggerPolicy, make_mtdagger_pre_post_processors
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import per_task_means

logger = logging.getLogger(__name__)

LOSS_SAMPLES_PER_TASK = 1024

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

    @staticmethod
    def concat(parts: Sequence[TrainingData]) -> TrainingData:
        """The frames of ``parts`` one after the other (e.g. rounds loaded once and kept in memory).

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
            inputs={k: torch.cat([p.inputs[k] for p in parts]) for k in keys},
            action=torch.cat([p.action for p in parts]),
            task_index=torch.cat([p.task_index for p in parts]),
            episode_id=torch.cat([p.episode_id for p in parts]),
        )


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
        normalised = preprocessor(dict(vector))
        self.vector = {k: normalised[k] for k in vector}
        self.device = self.vector["action"].device
        self.task_index = data.task_index.to(self.device, dtype=torch.long)

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
    ``heldout``: hold out ``heldout_fraction`` of each task's episodes OF EACH ROUND (at least one
    where the round has two or more) and measure on them. The choice depends only on ``seed``, the
    round and its episodes, so an episode held out in one phase is held out in every later phase
    (pass the experiment's seed, not a per-phase one): a warm-started policy never trained on it.
    """
    all_index = torch.arange(len(data))
    if split == "heldout":
        held_ids = heldout_episodes(data, heldout_fraction, seed)
        held = torch.from_numpy(np.isin(data.episode_id.numpy(), held_ids))
        return all_index[~held], all_index[held]
    generator = np.random.default_rng(seed)
    measure = []
    for task in torch.unique(data.task_index).tolist():
        task_index = all_index[data.task_index == task].numpy()
        size = min(LOSS_SAMPLES_PER_TASK, len(task_index))
        measure.append(np.sort(generator.choice(task_index, size=size, replace=False)))
    return all_index, torch.from_numpy(np.concatenate(measure))


def heldout_episodes(data: TrainingData, heldout_fraction: float, seed: int) -> list[int]:
    """Episode ids held out, chosen per (round, task) from that round's episodes of the task alone."""
    episode_ids = data.episode_id.numpy()
    task_index = data.task_index.numpy()
    chosen: list[int] = []
    for round_position in np.unique(episode_ids // EPISODE_ID_STRIDE).tolist():
        in_round = episode_ids // EPISODE_ID_STRIDE == round_position
        for task in np.unique(task_index[in_round]).tolist():
            episodes = np.unique(episode_ids[in_round & (task_index == task)])
            count = int(round(heldout_fraction * len(episodes)))
            count = min(max(count, 1 if len(episodes) > 1 else 0), len(episodes) - 1)
            generator = np.random.default_rng(np.random.SeedSequence([seed, round_position, task]))
            chosen += generator.choice(episodes, size=count, replace=False).tolist()
    return chosen


@torch.no_grad()
def per_task_loss(
    policy: MTDAggerPolicy, data: NormalisedData, index: torch.Tensor, num_tasks: int
) -> tuple[list, list]:
    """Mean MSE per task over the frames at ``index`` (None where a task has none) and the counts."""
    policy.eval()
    sums = torch.zeros(num_tasks, dtype=torch.float64, device=data.device)
    counts = torch.zeros(num_tasks, dtype=torch.float64, device=data.device)
    for chunk in torch.split(index, 4096):
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
    for chunk in torch.split(index, 4096):
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
    log_interval: int = LOG_INTERVAL,
    sampling: str = "uniform",
) -> PhaseResult:
    """Trains ``policy`` for ``steps`` AdamW steps and measures the per-task loss drop.

    Each step samples ``batch_size`` frames of ``train_index`` with replacement (uniformly, or with
    ``sampling="balanced"`` a task uniformly and then one of its frames uniformly) and takes
    one AdamW step on ``policy.imitation_loss`` with the gradient norm clipped to
    ``config.optimizer_grad_clip_norm``. The losses stay on the device: they are read back only every
    ``log_interval`` steps and after the last one, where they are checked for NaN/inf and reported.
    The first step of each interval calls the full ``policy.forward`` (same loss and gradient) and
    logs its per-task losses at debug level. The result depends only on the inputs and ``seed``
    (not on ``log_interval``).

    Args:
        policy: The policy to train, in place; its ``task_names`` must be ``data.task_names``.
        data: The normalised frames.
        train_index: Frames to train on.
        loss_index: Frames the per-task loss is measured on, before and after.
        steps: Optimiser steps.
        batch_size: Frames per step (capped at ``len(train_index)``).
        lr: AdamW learning rate.
        seed: Seed of the batch sampling.
        on_step: Progress callback, called every ``log_interval`` steps and after the last step as
            ``on_step(steps_done, mean_loss)``: the number of steps completed so far (1..steps) and the
            mean training loss over the steps since the previous call.
        log_interval: Steps between two reads of the loss.
        sampling: ``uniform`` over frames or ``balanced`` over tasks.

    Returns:
        The per-task losses at the start and at the end, the gain and the last FINAL_LOSSES step
        losses.

    Raises:
        ValueError: If the policy's task vocabulary differs from the data's, log_interval < 1 or
            ``sampling`` is unknown.
        FloatingPointError: If the loss becomes NaN or infinite (nothing is committed then).
    """
    if list(policy.config.task_names) != data.task_names:
        raise UserError(
            f"The policy's tasks {policy.config.task_names} differ from the data's {data.task_names}."
        )
    if log_interval < 1:
        raise ValueError(f"log_interval must be >= 1, got {log_interval}.")
    num_tasks = len(data.task_names)
    loss_start, _ = per_task_loss(policy, data, loss_index, num_tasks)
    generator = torch.Generator().manual_seed(seed)
    draw = batch_sampler(train_index, data.data.task_index, sampling, generator)
    optimizer = make_optimizer(policy, lr)
    parameters = [p for p in policy.parameters() if p.requires_grad]
    clip_norm = policy.config.optimizer_grad_clip_norm
    size = min(batch_size, len(train_index))
    policy.train()
    window: list[torch.Tensor] = []
    tail = torch.empty(0)  # the last FINAL_LOSSES step losses, on the CPU
    picks = torch.empty(0, dtype=torch.long)
    for step in range(steps):
        offset = step % log_interval
        if offset == 0:
            # One interval's batch indices at once, drawn on the CPU (device independent).
            block = min(log_interval, steps - step)
            picks = draw((block, size)).to(data.device)
        batch = data.batch(picks[offset])
        if offset == 0:
            loss, info = policy.forward(batch)
            _check_finite(loss.detach().reshape(1), step)
            info = info or {}
            logger.debug("step %d: loss %s, per task %s", step, info.get("loss"), info.get("per_task_loss"))
        else:
            loss = policy.imitation_loss(batch, task_index=batch["task_index"])
        optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(parameters, clip_norm, foreach=True)
        optimizer.step()
        window.append(loss.detach())
        if offset == log_interval - 1 or step == steps - 1:
            losses = torch.stack(window).float().cpu()  # the one sync of the interval
            _check_finite(losses, step + 1 - len(window))
            window = []
            tail = torch.cat([tail, losses])[-FINAL_LOSSES:]
            if on_step is not None:
                on_step(step + 1, float(losses.double().mean()))
    loss_end, counts = per_task_loss(policy, data, loss_index, num_tasks)
    return PhaseResult(
        loss_start=loss_start,
        loss_end=loss_end,
        gain=performance_gain(loss_start, loss_end),
        train_loss=tail.tolist(),
        loss_samples=counts,
    )


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
