"""A phase's optimiser steps through the student's seam (``phase_ops``), and what they record.

Each step samples ``batch_size`` training frames with replacement (``uniform``, or ``balanced``: a
task, then one of its frames) and takes one optimiser step on the student's loss. The losses stay
on the device and are read back, checked for NaN/inf and reported every ``log_interval`` steps.
"""

from __future__ import annotations

import logging
import time
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

import torch
from lerobot.policies.pretrained import PreTrainedPolicy

from lerobot_mtdagger.policies.task_conditioning import TASK_FEATURE
from lerobot_mtdagger.runner.student import Student, TrainingOps, student_of_policy
from lerobot_mtdagger.runner.training.normalise import NormalisedData
from lerobot_mtdagger.runner.training.phase_progress import PhaseProgress, loop_state, restore_loop
from lerobot_mtdagger.runner.training.plateau import PlateauStop, PlateauTracker
from lerobot_mtdagger.runner.training.task_loss import performance_gain
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)


LOG_INTERVAL = 100
"""Steps between two syncs of the training loss (finiteness check, progress callback, debug log)."""


FINAL_LOSSES = 10
"""Step losses kept in ``PhaseResult.train_loss`` (the last ones of the phase)."""


@dataclass
class PhaseResult:
    """Per-task losses of one training phase (lists aligned with the task names; None: no sample).

    Attributes:
        loss_start: Per-task loss before training.
        loss_end: Per-task loss of the returned weights.
        gain: ``max(0, loss_start - loss_end)`` per task.
        train_loss: The last FINAL_LOSSES step losses.
        loss_samples: Frames per task behind the losses.
        steps: Optimiser steps taken (fewer where a plateau stopped the phase).
        best_step: With a plateau stop, the step whose weights are returned (0: the initial ones).
        heldout_loss: With a plateau stop, ``[step, mean held-out loss]`` at every measurement.
        steps_s: Seconds spent in the optimiser steps (of every process, if resumed).
        task_loss_s: Seconds spent measuring the per-task loss.
        passes_per_task: Per task, frames drawn over training frames (None: no training frame).
        resumed_after_steps: The steps after which the phase was resumed (empty: in one go).
        earlier_steps_s: Of ``steps_s``, the seconds of the processes before the last resume.
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
    resumed_after_steps: list[int] = field(default_factory=list)
    earlier_steps_s: float = field(default=0.0, compare=False)


def phase_ops(
    policy: PreTrainedPolicy,
    data: NormalisedData,
    options: StepOptions,
    student: Student[Any, Any] | None = None,
) -> TrainingOps:
    """The training seam of ``policy``: ``student.phase_ops`` (None: the one registered for its type)."""
    student = student_of_policy(policy) if student is None else student
    return student.phase_ops(policy, data, options)


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
        lr_schedule: ``constant`` or ``cosine`` over ``steps`` (``mtdagger`` only).
        plateau: Stop at the held-out loss's plateau, keeping its best weights (None: all ``steps``).
        log_interval: Steps between two reads of the loss.
        task_dropout: A LeRobot student's task dropout (``mtdagger``'s is in its config).
        progress: Where the phase's progress is saved and resumed from (None: never saved).
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
    progress: PhaseProgress | None = None


def train_phase(
    policy: PreTrainedPolicy,
    data: NormalisedData,
    train_index: torch.Tensor,
    loss_index: torch.Tensor,
    options: StepOptions,
    on_step: Callable[[int, float], None] | None = None,
    student: Student[Any, Any] | None = None,
) -> PhaseResult:
    """Trains ``policy`` in place for ``options.steps`` steps (or to a plateau); measures the loss drop.

    ``loss_index`` frames measure the loss before and after. ``on_step(steps_done, mean_loss)`` is
    called every ``log_interval`` steps and after the last. The result depends only on the inputs and
    ``options.seed``.

    Raises:
        ValueError: If the policy's task vocabulary differs from the data's, log_interval < 1,
            ``sampling`` is unknown or ``plateau`` has no held-out frame.
        FloatingPointError: If the loss becomes NaN or infinite (nothing is committed then).
    """
    _check_phase_inputs(policy, data, options.log_interval, options.plateau)
    num_tasks = len(data.task_names)
    ops = phase_ops(policy, data, options, student)
    started = time.perf_counter()
    loss_start, _ = ops.task_losses(loss_index, num_tasks)
    measured = time.perf_counter()
    loop = StepLoop(ops, data, train_index, options, on_step)
    done = loop.run()
    trained = time.perf_counter()
    loss_end, counts = ops.task_losses(loss_index, num_tasks)
    return PhaseResult(
        loss_start=loss_start,
        loss_end=loss_end,
        gain=performance_gain(loss_start, loss_end),
        train_loss=loop.losses.tail.tolist(),
        loss_samples=counts,
        steps=done,
        best_step=None if loop.tracker is None else loop.tracker.best_step,
        heldout_loss=None if loop.tracker is None else loop.tracker.curve,
        steps_s=trained - measured + loop.earlier_steps_s,
        task_loss_s=(measured - started) + (time.perf_counter() - trained),
        passes_per_task=loop.draws.passes(),
        resumed_after_steps=loop.resumed_after_steps,
        earlier_steps_s=loop.earlier_steps_s,
    )


class StepLoop:
    """A phase's optimiser steps: batches drawn an interval at a time, losses read back per interval."""

    def __init__(
        self,
        ops: TrainingOps,
        data: NormalisedData,
        train_index: torch.Tensor,
        options: StepOptions,
        on_step: Callable[[int, float], None] | None,
    ) -> None:
        """Builds the sampler, the optimiser (over ``options.steps``) and the plateau tracker."""
        self.ops, self.data, self.options = ops, data, options
        self.generator = torch.Generator().manual_seed(options.seed)
        self.draw = batch_sampler(train_index, data.data.task_index, options.sampling, self.generator)
        self.optimizer, self.scheduler, self.clip_norm = ops.optimizer(options.steps)
        self.parameters = [p for p in ops.policy.parameters() if p.requires_grad]
        self.size = min(options.batch_size, len(train_index))
        self.tracker = None if options.plateau is None else PlateauTracker(options.plateau, ops, data)
        self.losses = _LossWindow(on_step)
        self.draws = DrawCounter(data.data.task_index, train_index, len(data.task_names))
        # Progress is saved part-way only without a plateau stop (its curve and best weights are not).
        self.progress = options.progress if self.tracker is None else None
        self.earlier_steps_s = 0.0  # seconds earlier processes spent in the steps of a resumed phase
        self.resumed_after_steps: list[int] = []

    def run(self) -> int:
        """Takes the steps (to the cap or a plateau, restoring its best weights); returns the steps taken.

        Resumes from and saves the phase's progress (``progress.every_s``).
        """
        steps, log_interval = self.options.steps, self.options.log_interval
        stopped = self.tracker is not None and self.tracker.measure(0)
        self.ops.policy.train()
        picks = torch.empty(0, dtype=torch.long)
        done = restore_loop(self, self.progress.load()) if self.progress is not None else 0
        started = time.perf_counter()
        while done < steps and not stopped:
            offset = done % log_interval
            if offset == 0:
                if done > 0 and self.progress is not None and self.progress.due():
                    steps_s = self.earlier_steps_s + time.perf_counter() - started
                    self.progress.save(done, loop_state(self), steps_s)
                # One interval's batch indices at once, drawn on the CPU (device independent).
                drawn = self.draw((min(log_interval, steps - done), self.size))
                self.draws.start_interval(drawn)
                picks = drawn.to(self.data.device)
            self.draws.count(offset)
            self.step(picks[offset], offset, done)
            done += 1
            if offset == log_interval - 1 or done == steps:
                self.losses.flush(done)
            if self.tracker is not None and (done % self.tracker.stop.every == 0 or done == steps):
                self.losses.flush(done)
                stopped = self.tracker.measure(done)
        if self.tracker is not None:
            self.tracker.restore_best()
        return done

    def step(self, batch: torch.Tensor, offset: int, done: int) -> None:
        """One optimiser step on the frames ``batch`` (the interval's step ``offset``; ``done`` before it)."""
        loss = self.ops.step_loss(batch, first_of_interval=offset == 0)
        if offset == 0:
            _check_finite(loss.detach().reshape(1), done)
        self.optimizer.zero_grad(set_to_none=True)
        loss.backward()
        torch.nn.utils.clip_grad_norm_(self.parameters, self.clip_norm, foreach=True)
        self.optimizer.step()
        if self.scheduler is not None:
            self.scheduler.step()
        self.losses.add(loss)


def _check_phase_inputs(
    policy: PreTrainedPolicy, data: NormalisedData, log_interval: int, plateau: PlateauStop | None
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

    ``uniform``: every frame equally likely; ``balanced``: a task with training frames uniformly, then
    one of its frames (``ValueError`` for another ``sampling``).
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


def _check_finite(losses: torch.Tensor, first_step: int) -> None:
    """Raises FloatingPointError at the first NaN/inf of ``losses`` (step ``first_step`` onwards)."""
    finite = torch.isfinite(losses)
    if not bool(finite.all()):
        bad = int(torch.nonzero(~finite)[0, 0])
        raise FloatingPointError(
            f"Training loss became {float(losses[bad])} at step {first_step + bad}; nothing was committed."
        )
