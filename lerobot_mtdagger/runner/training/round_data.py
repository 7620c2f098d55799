"""A run's committed rounds as training frames, read once straight from each dataset's parquet files.

A phase joins them (``TrainingData.concat``): vectors concatenated, images and point clouds left in
their rounds as ``FrameParts``.
"""

from __future__ import annotations

import io
import json
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import cast

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq
import torch

from lerobot_mtdagger.runner.training.frame_parts import FrameTensor, join_frames

EPISODE_ID_STRIDE = 1_000_000
"""``episode_id = episode_index + round_position * EPISODE_ID_STRIDE``."""


@dataclass
class TrainingData:
    """Frames of several rounds in memory.

    Attributes:
        inputs: Observation tensors by key; images uint8 (N, H, W, 3), the rest float32; images and
            point clouds of several rounds as ``FrameParts``.
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
        """The frames of ``parts`` one after the other (``ValueError`` if none, or their keys differ)."""
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
    if len(tensors[0].shape) <= 2:  # vectors: always plain tensors (only images and clouds are parts)
        return torch.cat(cast("list[torch.Tensor]", tensors))
    return join_frames(tensors)


def load_round(root: Path, round_position: int, input_keys: Sequence[str]) -> TrainingData:
    """Loads one committed round dataset into memory, straight from its parquet files.

    The frames are read with pyarrow in ``LeRobotDataset``'s order, images decoded with PIL.
    ``round_position`` offsets the episode ids so they stay unique across rounds.

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
    inputs: dict[str, FrameTensor] = {}
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
    values: np.ndarray = np.array(array.to_numpy(zero_copy_only=False), dtype=dtype)  # owned, writable
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
