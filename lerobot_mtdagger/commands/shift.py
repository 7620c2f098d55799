"""``lerobot-mtdagger shift``: a pretrained policy's covariate shift, per task.

Its action error on the states of its own rollouts against on the expert's: whether DAgger's relabelled
rollouts have much to add over more demonstrations. The options are ``eval``'s (``configs/shift.py``).
"""

from __future__ import annotations

import json

import numpy as np

from lerobot_mtdagger.analysis.shift import ShiftResult, measure_shift
from lerobot_mtdagger.commands.configs.shift import ShiftConfig
from lerobot_mtdagger.commands.eval import check_policy, suite_and_policy

__all__ = ["ShiftConfig", "shift_command", "shift_table"]


def shift_command(config: ShiftConfig) -> dict:
    """Measures a pretrained policy's covariate shift per task and prints it."""
    unverified = check_policy(config)
    suite, runner = suite_and_policy(config)
    with config.env_workers(suite) as workers:
        result = measure_shift(workers, runner, config.episodes, config.seed)
    print(shift_table(result))
    values = result.to_dict() | ({"unverified": unverified} if unverified else {})
    if config.output is not None:
        config.output.write_text(json.dumps(values, indent=2))
    return values


def shift_table(result: ShiftResult) -> str:
    """One line per task: success, mean squared action error on own and expert states, their ratio."""
    lines = [f"{'task':<32} {'success':>7} {'own states':>10} {'expert states':>13} {'own/expert':>10}"]
    rows = zip(
        result.task_names, result.success, result.own_error, result.expert_error, result.ratio, strict=True
    )
    for task, success, own, expert, ratio in rows:
        lines.append(f"{task:<32} {success:7.3f} {own:10.4f} {expert:13.4f} {ratio:10.2f}")
    own, expert = float(np.mean(result.own_error)), float(np.mean(result.expert_error))
    lines.append(
        f"{'mean':<32} {np.mean(result.success):7.3f} {own:10.4f} {expert:13.4f} {result.mean_ratio:10.2f}"
    )
    lines.append(f"median task's own/expert ratio: {result.median_ratio:.2f}")
    own_by_dimension = np.mean(result.own_error_by_dimension, axis=0)
    expert_by_dimension = np.mean(result.expert_error_by_dimension, axis=0)
    lines.append(
        f"mean error per action dimension, own states:    {np.array2string(own_by_dimension, precision=4)}"
    )
    lines.append(
        f"mean error per action dimension, expert states: {np.array2string(expert_by_dimension, precision=4)}"
    )
    return "\n".join(lines)
