"""One training phase of a run: the student built or warm-started, trained on D(k), saved and recorded."""

from __future__ import annotations

import time
from collections.abc import Sequence
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

import torch
from tqdm import tqdm

from lerobot_mtdagger.datasets.records import PhaseRecord
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.training.normalise import NormalisedData, compute_stats
from lerobot_mtdagger.runner.training.phase_progress import PhaseProgress, phase_key
from lerobot_mtdagger.runner.training.plateau import plateau_stop
from lerobot_mtdagger.runner.training.provenance import training_environment
from lerobot_mtdagger.runner.training.round_data import TrainingData, load_round
from lerobot_mtdagger.runner.training.splits import heldout_mask, normalisation_frames, split_frames
from lerobot_mtdagger.runner.training.steps import PhaseResult, StepOptions, train_phase
from lerobot_mtdagger.runner.training.task_loss import performance_gain
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.seeds import TRAINING_STREAM, stream_seed


def save_policy(policy: MTDAggerPolicy, preprocessor: Any, postprocessor: Any, folder: Path) -> None:
    """Writes a LeRobot pretrained model folder (config, weights, processors)."""
    policy.save_pretrained(folder)
    preprocessor.save_pretrained(folder)
    postprocessor.save_pretrained(folder)


class RoundCache:
    """Committed rounds read once per run and kept in memory (committed rounds never change)."""

    def __init__(self) -> None:
        self.rounds: list[TrainingData] = []

    def load(self, roots: Sequence[Path], input_keys: Sequence[str]) -> TrainingData:
        """D(k) for the round folders ``roots`` (rounds 0..k in order); only new rounds are read."""
        for position in range(len(self.rounds), len(roots)):
            self.rounds.append(load_round(roots[position], position, input_keys))
        return TrainingData.concat(self.rounds[: len(roots)])


def student_config(
    config: RunConfig, features: dict[str, Any], task_names: Sequence[str], unseen: bool
) -> Any:
    """The run's student's policy config on a suite's ``features`` (``unseen``: it has held-out tasks)."""
    return config.student.policy_config(config.policy, features, task_names, unseen)


@dataclass
class TrainedPhase:
    """A trained student with its processors and what its phase measured.

    Attributes:
        policy: The trained policy.
        preprocessor: Its pre-processor (normalisation statistics of the phase's frames).
        postprocessor: Its post-processor.
        result: The per-task losses and steps of the phase.
        loss_previous: The previous phase's policy's per-task loss on this phase's loss frames (None in
            round 0): what performance gain starts from.
        frames: Frames of D(k).
        prepare_s: Seconds spent before the first step.
        train_s: Seconds spent training.
    """

    policy: MTDAggerPolicy
    preprocessor: Any
    postprocessor: Any
    result: PhaseResult
    loss_previous: list[float | None] | None
    frames: int
    prepare_s: float
    train_s: float

    @property
    def gain(self) -> list[float] | None:
        """Performance gain per task against the previous phase's policy (None in round 0)."""
        if self.loss_previous is None:
            return None
        return performance_gain(self.loss_previous, self.result.loss_end)

    def save(self, folder: Path) -> None:
        """Writes the LeRobot pretrained model folder."""
        save_policy(self.policy, self.preprocessor, self.postprocessor, folder)

    def record(
        self, round_index: int, gain_split: str, demos: list[int], timings: dict[str, float]
    ) -> PhaseRecord:
        """The phase's record without its evaluations (``eval`` and ``heldout_eval`` are None)."""
        result = self.result
        return PhaseRecord(
            round=round_index,
            trained_on_rounds=list(range(round_index + 1)),
            frames=self.frames,
            steps=result.steps,
            gain_split=gain_split,
            loss_start=result.loss_start,
            loss_end=result.loss_end,
            gain=self.gain,
            loss_previous=self.loss_previous,
            loss_samples=result.loss_samples,
            final_train_loss=result.train_loss,
            eval=None,
            heldout_eval=None,
            demos_per_task=demos,
            timings=timings,
            best_step=result.best_step,
            heldout_loss=result.heldout_loss,
            environment=training_environment(next(self.policy.parameters()).device),
            passes_per_task=result.passes_per_task,
            resumed_after_steps=result.resumed_after_steps,
        )


def train_on_rounds(
    config: RunConfig,
    policy_cfg: Any,
    data: TrainingData,
    round_index: int,
    previous: Path | None,
    show_progress: bool = False,
    progress_path: Path | None = None,
) -> TrainedPhase:
    """Algorithm 1's "Train Policy" for round ``round_index`` (k) of a run: trains a student on D(k).

    Splits and normalises the frames, builds the student (warm-started from round k-1's policy folder
    ``previous`` if the run says so), measures the previous policy's per-task loss and trains.
    ``progress_path``: where the phase's progress is saved (None: never).
    """
    start = time.perf_counter()
    image_keys = list(policy_cfg.image_features)
    phase_seed = stream_seed(config.training_seed, TRAINING_STREAM, round_index)
    split = split_frames(
        data,
        config.training.gain_split,
        config.training.heldout_fraction,
        config.seed,
        hold_out=config.training.steps_rule == "plateau",
    )
    stats = compute_stats(data, image_keys, normalisation_frames(config, data, split.train))
    torch.manual_seed(phase_seed)
    student = config.student
    policy, preprocessor, postprocessor = student.make_policy(policy_cfg, stats)
    runner = None if previous is None else PolicyRunner.from_pretrained(previous, config.policy.device)
    if runner is not None and config.training.warm_start:
        policy.load_state_dict(runner.policy.state_dict())
    normalised = NormalisedData(data, preprocessor, image_keys, list(policy_cfg.task_names))
    assert config.training.sampling is not None  # filled by RunConfig's preset
    options = StepOptions(
        steps=config.phase_steps(len(split.train)),
        batch_size=config.policy.batch_size,
        lr=getattr(config.policy, student.lr_option),
        seed=phase_seed,
        sampling=config.training.sampling,
        lr_schedule=config.training.lr_schedule,
        plateau=plateau_stop(config, split),
        task_dropout=getattr(policy_cfg, "task_dropout", 0.0),
    )
    if progress_path is not None:
        key = phase_key(round_index, config.student_type, options, split.train)
        options = replace(
            options, progress=PhaseProgress(progress_path, key, config.training.progress_every_s)
        )
    loss_previous = (
        None if runner is None else student.previous_losses(runner, normalised, split.loss, options)
    )
    prepared = time.perf_counter()
    with tqdm(
        total=options.steps, desc=f"round {round_index} train", leave=False, disable=not show_progress
    ) as bar:
        result = train_phase(
            policy,
            normalised,
            split.train,
            split.loss,
            options,
            on_step=lambda done, _: bar.update(done - bar.n),
            student=student,
        )
    return TrainedPhase(
        policy=policy,
        preprocessor=preprocessor,
        postprocessor=postprocessor,
        result=result,
        loss_previous=loss_previous,
        frames=len(data),
        prepare_s=prepared - start,
        train_s=time.perf_counter() - prepared + result.earlier_steps_s,
    )


def check_heldout(config: RunConfig, num_tasks: int) -> None:
    """Refuses ``steps_rule=plateau`` where round 0 holds no episode out (``UserError`` with the numbers)."""
    training, demos = config.training, config.dagger.initial_demos
    if training.steps_rule != "plateau":
        return
    assert demos is not None  # filled by RunConfig's preset
    fraction = training.heldout_fraction
    if not any(heldout_mask(demos, fraction, config.seed, task).any() for task in range(num_tasks)):
        raise UserError(
            f"--training.steps_rule=plateau needs held-out episodes, and round 0 would hold none out: a "
            f"task's first episode is always trained on, and --training.heldout_fraction={fraction} of "
            f"the other {demos - 1} per task gives none. Raise --training.heldout_fraction or "
            "--dagger.initial_demos, or choose --training.steps_rule=fixed or epochs."
        )
