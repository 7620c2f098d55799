"""Performance gain: what a phase's training did to each task's imitation loss.

Algorithm 1, "Train Policy": each task's imitation loss (the student's ``task_losses``; for
``mtdagger``, ``students.mtdagger.per_task_loss``) is recorded at the start and at the end of the
phase, on the training data itself or on a held-out split of episodes; the gain is
``max(0, L_start - L_end)`` per task.
"""

from __future__ import annotations


def performance_gain(loss_before: list[float | None], loss_after: list[float | None]) -> list[float]:
    """``max(0, L_before - L_after)`` per task (0 where a task has no measured loss)."""
    return [
        max(0.0, before - after) if before is not None and after is not None else 0.0
        for before, after in zip(loss_before, loss_after, strict=True)
    ]
