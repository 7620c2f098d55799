"""How much covariate shift do the study's policies meet? Their error on their own states vs the expert's.

``lerobot-mtdagger shift`` (``shift.measure_shift``) for BC at several budgets and Uniform DAgger's
policy at the same demos per task, seed 0 of the study, on the first ``EPISODES`` evaluation episodes
of every task (reset seeds no policy trained on). Per task: the squared action error
``|pi(s) - pi*(s)|^2`` on the states of the policy's own rollouts (also split into its successful and
failed episodes) and on the expert's rollouts from the same reset seeds; then averaged over tasks.
From the repository root, after the study's seed 0 (one core; about two minutes per policy):

    .venv/bin/python experiments/mt50-state-eval/covariate_shift.py [SEED]

SEED is the study's seed (default 0); a policy whose run has not made it yet is left out. It prints
two tables (kept in ``covariate_shift_seed<SEED>.txt``) and writes every per-task value to
``covariate_shift_seed<SEED>.json``.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import torch

from lerobot_mtdagger.analysis.shift import ShiftResult, measure_shift
from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers

RUNS = Path("outputs/mt50-state-eval/runs")
HERE = Path("experiments/mt50-state-eval")
EPISODES = 5
BC_BUDGETS = (3, 6, 12, 21, 33)
UNIFORM_PHASES = (1, 3, 6, 10)  # 3 (phase + 1) demos per task


def policies(seed: int) -> list[tuple[str, Path]]:
    """(label, policy folder) of BC at ``BC_BUDGETS`` and Uniform DAgger at the same demos per task."""
    bc = [(f"BC, {d} demos", RUNS / f"bc-{d}demos-seed{seed}" / "policies" / "round-000") for d in BC_BUDGETS]
    uniform = [
        (f"uniform, {3 * (p + 1)} demos", RUNS / f"uniform-seed{seed}" / "policies" / f"round-{p:03d}")
        for p in UNIFORM_PHASES
    ]
    return [(label, folder) for label, folder in [*bc, *uniform] if (folder / "model.safetensors").is_file()]


def summary_line(label: str, result: ShiftResult) -> str:
    """One table row: success, mean errors over tasks, ratio of the means, median per-task ratio."""
    succeeded = np.mean([e for e in result.own_error_succeeded if e is not None])
    failed = np.mean([e for e in result.own_error_failed if e is not None])
    return (
        f"| {label} | {np.mean(result.success):.3f} | {np.mean(result.own_error):.3f} | {succeeded:.3f} "
        f"| {failed:.3f} | {np.mean(result.expert_error):.3f} | {result.mean_ratio:.1f} "
        f"| {result.median_ratio:.1f} |"
    )


def dimension_line(label: str, result: ShiftResult) -> str:
    """One row of the second table: the mean error per action dimension, own states then expert states."""
    own = np.mean(result.own_error_by_dimension, axis=0)
    expert = np.mean(result.expert_error_by_dimension, axis=0)
    return f"| {label} | " + " | ".join(f"{value:.3f}" for value in [*own, *expert]) + " |"


def main() -> int:
    """Prints one table row per policy and writes every per-task value to ``covariate_shift_seed<S>.json``."""
    seed = int(sys.argv[1]) if len(sys.argv) > 1 else 0
    torch.set_num_threads(1)
    chosen = policies(seed)
    config = json.loads((chosen[0][1].parents[1] / "config.json").read_text())
    suite = make_suite(config["suite"], observation=ObservationConfig(obs_mode=config["obs_mode"]))
    print(f"{len(suite.task_names)} tasks, {EPISODES} evaluation episodes per task (seed {seed})\n")
    print(
        "| policy | success | error, own states | own, successful episodes | own, failed episodes "
        "| error, expert states | own / expert (means) | own / expert (median task) |"
    )
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    results = {}
    with EnvWorkers(suite, 0) as workers:
        for label, folder in chosen:
            results[label] = measure_shift(workers, PolicyRunner.from_pretrained(folder), EPISODES, seed)
            print(summary_line(label, results[label]), flush=True)
    print("\nMean squared error per action dimension (MetaWorld: x, y, z of the hand, gripper):\n")
    print(
        "| policy | own x | own y | own z | own gripper | expert x | expert y | expert z | expert gripper |"
    )
    print("|---|" + "---:|" * 8)
    for label, result in results.items():
        print(dimension_line(label, result))
    output = HERE / f"covariate_shift_seed{seed}.json"
    output.write_text(json.dumps({label: result.to_dict() for label, result in results.items()}, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
