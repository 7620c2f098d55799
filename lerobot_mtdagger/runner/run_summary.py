"""What a run says of its rounds: one summary line per round, also of a finished run resumed."""

from __future__ import annotations

import logging
from collections.abc import Callable

import numpy as np

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.runner.configs import RunConfig

logger = logging.getLogger(__name__)


def summary_line(experiment: ExperimentDir, round_index: int) -> str:
    """One line per round: demos so far, average success, allocation, time spent."""
    record = experiment.read_round_record(round_index)
    phase = experiment.read_phase_record(round_index)
    success = "n/a" if phase.eval_mean is None else f"{phase.eval_mean:.3f}"
    if phase.heldout_eval is not None:
        success += f" | unseen {phase.heldout_eval['mean']:.3f}"
    demos = np.mean(record.demos_so_far)
    timing = " ".join(f"{k}={v:.1f}" for k, v in phase.timings.items() if k not in PHASE_DETAIL_TIMINGS)
    return (
        f"round {round_index}: demos/task {demos:.1f} | eval success {success} | "
        f"allocation {record.episodes_per_task} | beta {record.beta:.2f} | {timing}"
    )


PHASE_DETAIL_TIMINGS = ("steps_s", "task_loss_s")
"""Parts of ``train_s`` kept in the phase's record (``training.json``) but not in the summary line."""


def last_round(config: RunConfig) -> int:
    """Index of the last round of a run (0 for BC, whose one round holds every demo)."""
    if config.is_bc:
        return 0
    assert config.dagger.rounds is not None  # filled by RunConfig's preset
    return config.dagger.rounds


def is_finished(experiment: ExperimentDir, last: int) -> bool:
    """Whether every round and phase up to ``last`` is committed (a resume then has nothing to do)."""
    wanted = set(range(last + 1))
    return wanted <= set(experiment.committed_rounds()) and wanted <= set(experiment.committed_phases())


def finished_summary(
    experiment: ExperimentDir, last: int, on_summary: Callable[[str], None] | None
) -> list[str]:
    """The summary lines of a finished run, read from its records; nothing is written to its folder."""
    lines = [summary_line(experiment, round_index) for round_index in range(last + 1)]
    for line in lines:
        logger.info(line)
        if on_summary is not None:
            on_summary(line)
    return lines
