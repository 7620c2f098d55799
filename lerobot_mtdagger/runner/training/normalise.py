"""Normalisation statistics of the training frames and the frames normalised for a phase.

The frames go through LeRobot's pre-processor, the one saved with the checkpoint, so training,
rollouts and ``lerobot-eval`` agree. Frames are read a chunk at a time: memory stays bounded.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any

import numpy as np
import torch

from lerobot_mtdagger.runner.training.frame_parts import FrameParts, FrameTensor, materialise
from lerobot_mtdagger.runner.training.round_data import TrainingData

STATS_CHUNK = 8192
"""Frames read at a time for the normalisation statistics."""


MEASURE_CHUNK = 4096
"""Frames per forward pass when measuring per-task losses on vector inputs."""


MEASURE_CHUNK_VISUAL = 256
"""The same with an image or point-cloud input (4 096 frames of 84 px RGB took about 3 GB)."""


def compute_stats(
    data: TrainingData, image_keys: Sequence[str], index: torch.Tensor | None = None
) -> dict[str, dict[str, np.ndarray]]:
    """Mean/std/min/max of the vector inputs and the action (point clouds per channel) over ``index``.

    ``image_keys`` have no statistics and are never read.
    """
    frames = torch.arange(len(data)) if index is None else index
    tensors = {k: v for k, v in data.inputs.items() if k not in image_keys} | {"action": data.action}
    return {key: channel_stats(tensor, frames) for key, tensor in tensors.items()}


def channel_stats(tensor: FrameTensor, frames: torch.Tensor) -> dict[str, np.ndarray]:
    """Mean/std/min/max over the last axis' channels of ``tensor[frames]``, in float64 then float32.

    Read in chunks merged by Chan et al.'s pairwise update, so point clouds are never copied whole.
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


class NormalisedData:
    """Training frames normalised once with the policy's pre-processor; tasks as ``task_names`` indices."""

    def __init__(
        self, data: TrainingData, preprocessor: Any, image_keys: Sequence[str], task_names: Sequence[str]
    ):
        """Normalises the vector inputs and the action (``ValueError``: a task outside ``task_names``)."""
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
        """The normalised batch at ``index``: vectors, images as float CHW in [0, 1], and ``task_index``."""
        index = index.to(self.device)
        batch = {k: v[index] for k, v in self.vector.items()}
        for key in self.image_keys:
            images = self.data.inputs[key][index.cpu()].to(self.device)
            batch[key] = images.permute(0, 3, 1, 2).float() / 255.0
        batch["task_index"] = self.task_index[index]
        return batch


def normalise_inputs(preprocessor: Any, vector: dict[str, FrameTensor]) -> dict[str, FrameTensor]:
    """``vector`` (the action and non-image inputs) through the pre-processor, ``FrameParts`` part by part."""
    whole = {k: v for k, v in vector.items() if not isinstance(v, FrameParts)}
    normalised = preprocessor(dict(whole))
    result: dict[str, FrameTensor] = {k: normalised[k] for k in whole}
    for key, parts in vector.items():
        if isinstance(parts, FrameParts):

            def normalise_part(part: torch.Tensor, key: str = key) -> torch.Tensor:
                return preprocessor({key: part})[key]

            result[key] = parts.map(normalise_part)
    return result
