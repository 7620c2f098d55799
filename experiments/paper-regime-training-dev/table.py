"""run.sh's rule applied: each arm's success per training, budget and seed, and its chosen training.

It also shows the passes each arm's phases made over each task's frames.

Usage (``lab`` on the path: ``PYTHONPATH=experiments``), from the repository root:
``.venv/bin/python experiments/paper-regime-training-dev/table.py outputs/paper-regime-training-dev``
(one compare folder per training and seed: ``<training>-seed<seed>``). Written with run.sh on
2026-11-28, before any of its runs. The last lines, ``Decision: the training of <arm> is <training>.``,
are what the evaluation study reads.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

import numpy as np

from lab.passes import compare_runs, phase_passes

ARMS = ("bc", "uniform", "need")
TRAININGS = ("plain", "cosine")
SEEDS = (100, 101)
BUDGETS = (6, 18, 30)
TIE = 0.005


def read_success(folder: Path) -> dict[tuple[str, str, int, int], float]:
    """``{(arm, training, seed, demos per task): mean success}`` from every ``results.csv``."""
    found: dict[tuple[str, str, int, int], float] = {}
    for training in TRAININGS:
        for seed in SEEDS:
            path = folder / f"{training}-seed{seed}" / "results.csv"
            if not path.is_file():
                continue
            with path.open() as handle:
                for row in csv.DictReader(handle):
                    arm = "bc" if row["bc"] == "True" else row["method"]
                    budget = round(float(row["demos_per_task_mean"]))
                    if arm in ARMS and budget in BUDGETS:
                        found[(arm, training, int(row["seed"]), budget)] = float(row["eval_success_mean"])
    return found


def choose(success: dict, arm: str) -> tuple[str | None, list[str]]:
    """The rule for one arm: the training with the higher mean over seeds and budgets (ties: plain)."""
    lines, means = [], {}
    for training in TRAININGS:
        values = [success.get((arm, training, seed, budget)) for seed in SEEDS for budget in BUDGETS]
        if any(v is None for v in values):
            lines.append(
                f"{arm}/{training}: {sum(v is not None for v in values)} of {len(values)} points done"
            )
            continue
        means[training] = float(np.mean(values))
        drops = [success[(arm, training, s, 30)] < success[(arm, training, s, 18)] for s in SEEDS]
        flag = " (loses success from 18 to 30 demos on both seeds: under-tuned)" if all(drops) else ""
        lines.append(f"{arm}/{training}: mean over seeds and budgets {means[training]:.3f}{flag}")
    if len(means) < len(TRAININGS):
        return None, lines
    chosen = "cosine" if means["cosine"] > means["plain"] + TIE else "plain"
    return chosen, lines


def passes(folder: Path) -> list[str]:
    """Mean, min and max passes over a task's frames per arm, training and seed, phase by phase."""
    lines = []
    for training in TRAININGS:
        for seed in SEEDS:
            for run in compare_runs(folder / f"{training}-seed{seed}"):
                cells = phase_passes(run)
                if cells:
                    lines.append(f"| {training} | {run.name} | " + "; ".join(cells) + " |")
    return lines


def main() -> None:
    """Prints the success table, each arm's decision and the passes."""
    folder = Path(sys.argv[1])
    success = read_success(folder)
    print("| arm | training | seed | " + " | ".join(f"{b} demos" for b in BUDGETS) + " |")
    print("|---|---|---:|" + "---:|" * len(BUDGETS))
    for arm in ARMS:
        for training in TRAININGS:
            for seed in SEEDS:
                cells = [success.get((arm, training, seed, b)) for b in BUDGETS]
                shown = " | ".join("-" if c is None else f"{c:.3f}" for c in cells)
                print(f"| {arm} | {training} | {seed} | {shown} |")
    print("\nPasses over each task's frames per phase (mean [min-max] over tasks):\n")
    print("| training | run | phases 0, 1, ... |\n|---|---|---|")
    print("\n".join(passes(folder)))
    print()
    for arm in ARMS:
        chosen, lines = choose(success, arm)
        print("\n".join(lines))
        print(f"Decision: the training of {arm} is {chosen}." if chosen else f"Decision: {arm}: not yet.")


if __name__ == "__main__":
    main()
