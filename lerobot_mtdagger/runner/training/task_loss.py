"""The per-task imitation loss that performance gain and the plateau stop measure, and the gain.

Algorithm 1, "Train Policy": each task's imitation loss is recorded at the start and at the end of
the phase, on the training data itself or on a held-out split of episodes; the gain is
``max(0, L_start - L_end)`` per task.
"""

from __future__ import annotations

from collections.abc import Callable

import torch

from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.policies.mtdagger.modeling_mtdagger import per_task_means
from lerobot_mtdagger.runner.training.normalise import NormalisedData


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


def performance_gain(loss_before: list[float | None], loss_after: list[float | None]) -> list[float]:
    """``max(0, L_before - L_after)`` per task (0 where a task has no measured loss)."""
    return [
        max(0.0, before - after) if before is not None and after is not None else 0.0
        for before, after in zip(loss_before, loss_after, strict=True)
    ]
