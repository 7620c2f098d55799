"""Performance gain: what a phase's training did to each task's loss (Algorithm 1, "Train Policy")."""

from __future__ import annotations


def performance_gain(loss_before: list[float | None], loss_after: list[float | None]) -> list[float]:
    """``max(0, L_before - L_after)`` per task (0 where a task has no measured loss)."""
    return [
        max(0.0, before - after) if before is not None and after is not None else 0.0
        for before, after in zip(loss_before, loss_after, strict=True)
    ]
