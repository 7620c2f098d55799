"""The evaluation-seed pixel study's outcomes, as ``run.sh`` fixed them before any run.

From the repository root, after ``run.sh``'s ``report``:
(``lab`` on the path: ``PYTHONPATH=experiments``)
``.venv/bin/python experiments/pixels-eval/table.py [experiments/pixels-eval/report/results.csv]``.

- Success at every budget (10-60 demos per task) for each method, per seed and mean.
- Primary: need - BC and need - uniform in mean success over 20-60 demos per task (the DAgger methods'
  phases 1-5, BC's budgets 20-60), paired over seeds, 95% t interval.
- Secondary: gain - BC and gain - uniform on the same window; on the three hardest tasks of each seed
  (lowest success of uniform's phase 0, ties by task order), need - uniform and gain - uniform at
  60 demos per task.
"""

from __future__ import annotations

import csv
import json
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lab.paired import paired_line

DEFAULT = Path("experiments/pixels-eval/report/results.csv")
METHODS = ("bc", "uniform", "need", "gain")
WINDOW = (20.0, 60.0)
HARDEST = 3


def load(path: Path) -> dict[str, dict[int, dict[float, list[float]]]]:
    """Per-task success by method, seed and demos per task."""
    table: dict[str, dict[int, dict[float, list[float]]]] = defaultdict(lambda: defaultdict(dict))
    with path.open() as handle:
        for row in csv.DictReader(handle):
            demos = float(row["demos_per_task_mean"])
            table[row["method"]][int(row["seed"])][demos] = json.loads(row["eval_success"])
    return table


def mean_success(curve: dict[float, list[float]], low: float, high: float, tasks=None) -> float:
    """Mean success over the points with ``low <= demos <= high`` (over ``tasks``; NaN if none)."""
    points = [
        np.mean(s if tasks is None else [s[t] for t in tasks]) for d, s in curve.items() if low <= d <= high
    ]
    return float(np.mean(points)) if points else float("nan")


def hardest_tasks(curve: dict[float, list[float]]) -> list[int]:
    """The HARDEST tasks with the lowest success at the curve's first point (ties: task order)."""
    first = curve[min(curve)]
    return sorted(range(len(first)), key=lambda t: (first[t], t))[:HARDEST]


def main(path: Path) -> None:
    """Prints the success table, the primary and the secondary outcomes."""
    table = load(path)
    seeds = sorted(set().union(*(table[m].keys() for m in METHODS if m in table)))
    budgets = sorted({d for m in table for s in table[m] for d in table[m][s]})
    print(f"| method | {' | '.join(f'{d:g}' for d in budgets)} |  (mean success; seeds {seeds})")
    print("|---|" + "---:|" * len(budgets))
    for method in METHODS:
        cells = []
        for demos in budgets:
            values = [np.mean(table[method][s][demos]) for s in seeds if demos in table[method].get(s, {})]
            cells.append(f"{np.mean(values):.3f} ({len(values)})" if values else "-")
        print(f"| {method} | {' | '.join(cells)} |")
    print(f"\nPrimary and secondary, mean success over {WINDOW[0]:g}-{WINDOW[1]:g} demos per task:")
    for method, baseline in (("need", "bc"), ("need", "uniform"), ("gain", "bc"), ("gain", "uniform")):
        pairs = [
            (
                mean_success(table[method].get(s, {}), *WINDOW),
                mean_success(table[baseline].get(s, {}), *WINDOW),
            )
            for s in seeds
        ]
        print(paired_line(f"{method} - {baseline}", pairs))
    print(f"\nThe {HARDEST} hardest tasks of each seed (uniform's phase 0), at {WINDOW[1]:g} demos per task:")
    for method in ("need", "gain"):
        pairs = []
        for seed in seeds:
            uniform = table["uniform"].get(seed, {})
            if not uniform:
                continue
            tasks = hardest_tasks(uniform)
            at_end = (WINDOW[1], WINDOW[1])
            pairs.append(
                (
                    mean_success(table[method].get(seed, {}), *at_end, tasks),
                    mean_success(uniform, *at_end, tasks),
                )
            )
        print(paired_line(f"{method} - uniform", pairs))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT)
