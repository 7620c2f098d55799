"""Per-task imitation loss of a LeRobot policy on LeRobot datasets: what ``plan``'s performance gain reads.

The paper's performance gain is the drop of each task's imitation loss over a training phase:
``max(0, L_before - L_after)`` on the phase's training data. Between two collection sessions that is
the loss of the policy before training (the one that collected the session) minus the loss of the
policy after it, both on the training datasets. Each loss is the policy's own ``forward`` loss (what
``lerobot-train`` minimises and the runner measures per task), averaged over every frame of a task:
the frames are read through LeRobot's ``LeRobotDataset`` with the policy's ``delta_timestamps`` (its
action chunk and observation history) and its saved pre-processor, one task's frames per batch,
without gradients, in eval mode, under a fixed seed (Diffusion's noise draw is random), so the same
weights on the same data always measure the same.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lerobot_mtdagger.planning.episodes import dataset_checksum, open_metadata
from lerobot_mtdagger.utils.errors import UserError

LOSS_BATCH = 64
"""Frames per forward pass (one task's frames at a time)."""
LOSS_SEED = 0
"""The seed every measurement runs under."""
GENERATED_INPUTS = ("observation.environment_state",)
"""Inputs a policy of this toolkit makes itself from the batch's task (``policies.task_conditioning``)."""


def policy_checksum(path: Path) -> str:
    """sha256 over a policy folder's files (names and bytes)."""
    hasher = hashlib.sha256()
    for file in sorted(p for p in Path(path).rglob("*") if p.is_file()):
        hasher.update(file.relative_to(path).as_posix().encode() + b"\0")
        hasher.update(hashlib.sha256(file.read_bytes()).digest())
    return hasher.hexdigest()


def per_task_loss(
    policy_path: Path, sources: Sequence[str], tasks: Sequence[str], batch_size: int = LOSS_BATCH
) -> tuple[list[float | None], list[int]]:
    """Each task's mean ``forward`` loss of the policy over every frame of the datasets, and the counts.

    Args:
        policy_path: A LeRobot pretrained policy folder (its processors saved with it).
        sources: LeRobot datasets (local folders or Hub repo ids).
        tasks: The plan's tasks, in order.
        batch_size: Frames per forward pass.

    Raises:
        UserError: If the folder is not a policy, or a dataset lacks one of the policy's inputs.
    """
    import torch

    from lerobot_mtdagger.datasets.checkpoints import load_policy

    policy, preprocessor, _ = load_policy(policy_path)
    policy.eval()
    sums, counts = [0.0] * len(tasks), [0] * len(tasks)
    for source in sources:
        dataset, task_of_frame = _dataset_for(policy, source, policy_path)
        for position, task in enumerate(tasks):
            frames = [i for i, name in enumerate(task_of_frame) if name == task]
            for start in range(0, len(frames), batch_size):
                chunk = frames[start : start + batch_size]
                batch = _collate(dataset, chunk)
                with torch.no_grad(), torch.random.fork_rng():
                    torch.manual_seed(LOSS_SEED)
                    loss, _ = policy.forward(preprocessor(batch))
                sums[position] += float(loss) * len(chunk)
                counts[position] += len(chunk)
    losses = [s / n if n else None for s, n in zip(sums, counts, strict=True)]
    return losses, counts


def _dataset_for(policy: Any, source: str, policy_path: Path) -> tuple[Any, list[str]]:
    """The LeRobot dataset with the policy's delta timestamps, and each frame's task."""
    from lerobot.datasets.factory import resolve_delta_timestamps
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    meta = open_metadata(source)
    needed = [key for key in policy.config.input_features if key not in GENERATED_INPUTS]
    missing = [key for key in needed if key not in meta.features]
    if missing:
        raise UserError(
            f"The policy {policy_path} reads {', '.join(missing)}, which {source} does not have: give the "
            "datasets it was trained on (--loss_datasets)."
        )
    dataset = LeRobotDataset(
        meta.repo_id,
        root=meta.root,
        delta_timestamps=resolve_delta_timestamps(policy.config, meta),
        video_backend="pyav",
    )
    names = {
        int(index): str(task) for task, index in zip(meta.tasks.index, meta.tasks["task_index"], strict=True)
    }
    return dataset, [names[int(i)] for i in dataset.hf_dataset["task_index"]]


def _collate(dataset: Any, frames: Sequence[int]) -> dict[str, Any]:
    """The frames as one batch (LeRobot's items stacked, strings as lists)."""
    from torch.utils.data import default_collate

    return default_collate([dataset[i] for i in frames])


def policy_inputs(policy_path: Path) -> dict[str, str]:
    """A policy folder as a plan records it: its path and checksum."""
    return {"policy": str(policy_path), "policy_sha256": policy_checksum(policy_path)}


def dataset_inputs(sources: Sequence[str]) -> list[dict[str, str]]:
    """The loss datasets as a plan records them: each source and its files' checksum."""
    return [{"source": s, "checksum": dataset_checksum(Path(open_metadata(s).root))} for s in sources]
