"""Which frames a phase trains on, measures its per-task loss on, and holds out (by episode)."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import torch

from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.training.round_data import EPISODE_ID_STRIDE, TrainingData
from lerobot_mtdagger.utils.sampling import systematic_picks
from lerobot_mtdagger.utils.seeds import HELDOUT_STREAM

LOSS_SAMPLES_PER_TASK = 1024


@dataclass(frozen=True)
class FrameSplit:
    """Which frames a phase trains on, measures the per-task loss on, and holds out (empty: none)."""

    train: torch.Tensor
    loss: torch.Tensor
    heldout: torch.Tensor


def split_frames(
    data: TrainingData, gain_split: str, heldout_fraction: float, seed: int, hold_out: bool = False
) -> FrameSplit:
    """Splits the frames of D(k) into training, loss-measurement and held-out frames.

    Episodes are held out (``heldout_episodes``) when ``gain_split == "heldout"`` or ``hold_out``; the
    loss is measured on them then, else on up to LOSS_SAMPLES_PER_TASK training frames per task. Pass
    the experiment's seed: an episode held out once stays held out in every later phase.
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

    A task's first episode is always trained on; of the others, the one at position ``j`` is held out
    when ``floor(f * (j + 1) + u)`` steps up at ``j`` (one offset ``u`` per seed and task). So any split
    into rounds holds out the same share, and a new round never moves an earlier episode.
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


def normalisation_frames(config: RunConfig, data: TrainingData, train_index: torch.Tensor) -> torch.Tensor:
    """The training frames the normalisation statistics come from: round 0's (``fixed``) or all."""
    if config.training.normalisation == "recompute":
        return train_index
    return train_index[data.episode_id[train_index] < EPISODE_ID_STRIDE]
