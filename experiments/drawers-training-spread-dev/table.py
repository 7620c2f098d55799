"""The spread between trainings on the same drawer data, as ``run.sh`` fixed it before any run.

From the repository root, after ``save_records.sh`` (or with ``outputs/`` still there):
``.venv/bin/python experiments/drawers-training-spread-dev/table.py [FOLDER]``, FOLDER holding the run
folders or their saved records (default: ``records/`` here).

- Per data seed: each training's mean in-domain and unseen success, their mean and sample SD over the
  trainings; the SD pooled over the data seeds (root of the mean variance).
- Per unseen drawer: the range of success over the trainings of each data seed.
- K = ceil(pooled_SD^2 / (S x 0.03^2)) trainings per seed and method, for S = 3 and S = 5 seeds.
- Refuses runs of one data seed whose round 0 differs (the trainings must share their frames).
"""

from __future__ import annotations

import math
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.results import experiment_rows
from lerobot_mtdagger.datasets.experiment_dir import open_run

DEFAULT = Path("experiments/drawers-training-spread-dev/records")
RUN_NAME = re.compile(r"^bc20-seed(\d+)-train(\d+)$")
TARGET_SE = 0.03
SEED_COUNTS = (3, 5)


def load(folder: Path) -> dict[int, dict[int, dict]]:
    """The evaluated row of every run, by data seed and training seed.

    Raises:
        SystemExit: If the trainings of one data seed did not share their round 0.
    """
    runs: dict[int, dict[int, dict]] = defaultdict(dict)
    digests: dict[int, dict] = {}
    for root in sorted(path for path in folder.iterdir() if RUN_NAME.match(path.name)):
        rows = experiment_rows(root)
        if not rows:
            continue  # not evaluated yet
        seed, training_seed = (int(group) for group in RUN_NAME.match(root.name).groups())
        files = open_run(root).read_round_record(0).files
        if digests.setdefault(seed, files) != files:
            raise SystemExit(f"{root.name}: its round 0 differs from another training of seed {seed}.")
        runs[seed][training_seed] = rows[-1]
    return runs


def spread_lines(runs: dict[int, dict[int, dict]], column: str, name: str) -> list[str]:
    """Per data seed the trainings' values, mean and SD of ``column``; then the pooled SD and K."""
    lines, variances = [], []
    for seed, trainings in sorted(runs.items()):
        if any(trainings[t][column] is None for t in trainings):
            lines.append(f"{name}, seed {seed}: not measured")
            continue
        values = [float(trainings[t][column]) for t in sorted(trainings)]
        listed = " / ".join(f"{v:.3f}" for v in values)
        if len(values) < 2:
            lines.append(f"{name}, seed {seed}: {listed} (fewer than 2 trainings)")
            continue
        sd = float(np.std(values, ddof=1))
        variances.append(sd**2)
        lines.append(f"{name}, seed {seed}: {listed}; mean {np.mean(values):.3f}, SD {sd:.3f}")
    if variances:
        pooled = math.sqrt(float(np.mean(variances)))
        needed = ", ".join(
            f"S={s}: K={max(1, math.ceil(pooled**2 / (s * TARGET_SE**2)))}" for s in SEED_COUNTS
        )
        pooled_line = f"{name}: pooled SD over {len(variances)} seed(s) {pooled:.3f}"
        lines.append(f"{pooled_line}; trainings per seed {needed}")
    return lines


def drawer_lines(runs: dict[int, dict[int, dict]]) -> list[str]:
    """Per data seed and unseen drawer: success of each training and its range."""
    lines = []
    for seed, trainings in sorted(runs.items()):
        first = next(iter(trainings.values()))
        for index, drawer in enumerate(first["unseen_tasks"] or []):
            values = [float(trainings[t]["unseen_success"][index]) for t in sorted(trainings)]
            listed = " / ".join(f"{v:.2f}" for v in values)
            lines.append(f"seed {seed}, {drawer}: {listed}; range {max(values) - min(values):.2f}")
    return lines


def main() -> None:
    """Prints the outcomes fixed in ``run.sh``."""
    folder = Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT
    runs = load(folder)
    if not runs:
        raise SystemExit(f"No evaluated run in {folder}: run run.sh (and save_records.sh) first.")
    print(f"Trainings on the same data (20 demos per drawer), from {folder}:")
    for line in spread_lines(runs, "eval_success_mean", "in-domain"):
        print(line)
    for line in spread_lines(runs, "unseen_success_mean", "unseen"):
        print(line)
    print("Per unseen drawer:")
    for line in drawer_lines(runs):
        print(line)


if __name__ == "__main__":
    main()
