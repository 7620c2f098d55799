"""The plateau stop: end a phase when the loss on held-out episodes stops improving."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np
import torch

from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.training.normalise import NormalisedData
from lerobot_mtdagger.runner.training.splits import FrameSplit


@dataclass(frozen=True)
class PlateauStop:
    """Ends a phase when the loss on held-out frames stops improving (``steps_rule=plateau``).

    The mean per-task loss on ``index`` is measured before the first step and every ``every`` steps;
    after ``patience`` measurements without a new minimum (or at the cap) the phase ends with the
    weights of the minimum.
    """

    index: torch.Tensor
    every: int
    patience: int


class PlateauTracker:
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


def plateau_stop(config: RunConfig, split: FrameSplit) -> PlateauStop | None:
    """The phase's plateau stop on the held-out frames (``steps_rule=plateau``), or None."""
    training = config.training
    if training.steps_rule != "plateau":
        return None
    return PlateauStop(index=split.heldout, every=training.plateau_every, patience=training.plateau_patience)
