"""Prints the beyond-plateau pilot's tables and its decision rule from the saved results table.

From the repository root, after ``run.sh`` (which copies nothing; the report it writes holds the
table): ``.venv/bin/python experiments/beyond-plateau-dev/table.py [results.csv]``.

- Success at 21, 33, 45 and 63 demos per task for BC, need and uniform, per seed and mean.
- The decision rule fixed before the runs (``run.sh``): per seed, need's mean success over its phases
  at 45-63 demos per task minus BC's mean over its budgets in 45-63, with the mean over seeds and its
  95% t interval; the extension is proposed if that mean exceeds 0.02 and need is ahead on every seed.
- The same difference for uniform, and need - uniform over 45-63 demos.
"""

from __future__ import annotations

import csv
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.stats import format_difference, paired_difference

DEFAULT = Path("experiments/beyond-plateau-dev/report/results.csv")
SHOWN = (21, 33, 45, 63)
WINDOW = (45, 63)
MARGIN = 0.02


def load(path: Path) -> dict[str, dict[int, dict[float, float]]]:
    """Average evaluation success by method, seed and demos per task."""
    table: dict[str, dict[int, dict[float, float]]] = defaultdict(lambda: defaultdict(dict))
    with path.open() as handle:
        for row in csv.DictReader(handle):
            table[row["method"]][int(row["seed"])][float(row["demos_per_task_mean"])] = float(
                row["eval_success_mean"]
            )
    return table


def window_mean(curve: dict[float, float]) -> float:
    """Mean success over the points with ``WINDOW[0] <= demos <= WINDOW[1]`` (NaN if none yet)."""
    points = [s for d, s in curve.items() if WINDOW[0] <= d <= WINDOW[1]]
    return float(np.mean(points)) if points else float("nan")


def main(path: Path) -> None:
    """Prints the tables and the verdict of the decision rule."""
    table = load(path)
    seeds = sorted(table["need"])
    print(f"| method | {' | '.join(f'{d} demos: seeds {seeds}' for d in SHOWN)} |")
    print("|---|" + "---|" * len(SHOWN))
    for method in ("bc", "need", "uniform"):
        cells = []
        for demos in SHOWN:
            values = [table[method][s].get(float(demos), np.nan) for s in seeds]
            cells.append(" / ".join(f"{v:.3f}" for v in values) + f" (mean {np.nanmean(values):.3f})")
        print(f"| {method} | {' | '.join(cells)} |")
    print()
    for method, baseline in (("need", "bc"), ("uniform", "bc"), ("need", "uniform")):
        pairs = [(window_mean(table[method][s]), window_mean(table[baseline][s])) for s in seeds]
        complete = [(x, y) for x, y in pairs if not np.isnan(x) and not np.isnan(y)]
        if not complete:
            print(f"{method} - {baseline}: no seed has both yet")
            continue
        a, b = zip(*complete, strict=True)
        difference = paired_difference(a, b)
        per_seed = " / ".join(f"{x - y:+.3f}" for x, y in zip(a, b, strict=True))
        window = f"{WINDOW[0]}-{WINDOW[1]}"
        print(f"{method} - {baseline}, mean over {window} demos: {per_seed}; {format_difference(difference)}")
    gaps = np.array([window_mean(table["need"][s]) - window_mean(table["bc"][s]) for s in seeds])
    gaps = gaps[~np.isnan(gaps)]
    proposed = gaps.mean() > MARGIN and bool((gaps > 0).all())
    verdict = "met" if proposed else "not met"
    print(f"\ndecision rule (mean > {MARGIN}, need ahead on every seed), {gaps.size} seeds: {verdict}")


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT)
