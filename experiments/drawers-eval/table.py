"""The evaluation-seed drawer study's outcomes, as ``run.sh`` fixed them before any run.

From the repository root, after ``run.sh``'s ``report``:
(``lab`` on the path: ``PYTHONPATH=experiments``)
``.venv/bin/python experiments/drawers-eval/table.py [experiments/drawers-eval/report/results.csv]``.

- Mean success at every budget (10, 20, 30 demos per drawer) for each method, on the 11 training
  drawers (in-domain) and on the 4 unseen ones, mean over seeds.
- Primary: need - BC and need - uniform in mean in-domain success over 20-30 demos per drawer (the
  DAgger methods' phases 1-2, BC's budgets 20 and 30), paired over seeds, 95% t interval.
- Secondary, on the same window: need - need_raw (the Kalman filter's effect), gain - BC,
  gain - uniform, uniform - BC; on the unseen drawers, each DAgger method - BC and need - uniform.
"""

from __future__ import annotations

import csv
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lab.paired import paired_line

DEFAULT = Path("experiments/drawers-eval/report/results.csv")
METHODS = ("bc", "uniform", "need", "need_raw", "gain")
WINDOW = (20.0, 30.0)
IN_DOMAIN = "eval_success_mean"
UNSEEN = "unseen_success_mean"
PRIMARY = (("need", "bc"), ("need", "uniform"))
SECONDARY = (("need", "need_raw"), ("gain", "bc"), ("gain", "uniform"), ("uniform", "bc"))
UNSEEN_PAIRS = (("uniform", "bc"), ("need", "bc"), ("need_raw", "bc"), ("gain", "bc"), ("need", "uniform"))

Curves = dict[str, dict[int, dict[float, float]]]


def load(path: Path, column: str) -> Curves:
    """Mean success (``column`` of ``results.csv``) by method, seed and demos per drawer."""
    table: Curves = defaultdict(lambda: defaultdict(dict))
    with path.open() as handle:
        for row in csv.DictReader(handle):
            if row[column] not in ("", "null", "None"):
                table[row["method"]][int(row["seed"])][float(row["demos_per_task_mean"])] = float(row[column])
    return table


def window_mean(curve: dict[float, float]) -> float:
    """Mean success over the points inside ``WINDOW`` (NaN if none)."""
    points = [success for demos, success in curve.items() if WINDOW[0] <= demos <= WINDOW[1]]
    return float(np.mean(points)) if points else float("nan")


def difference_line(table: Curves, method: str, baseline: str, seeds: list[int]) -> str:
    """``method - baseline``: per-seed window differences and their mean with the 95% t interval."""
    pairs = [(window_mean(table[method].get(s, {})), window_mean(table[baseline].get(s, {}))) for s in seeds]
    return paired_line(f"{method} - {baseline}", pairs)


def success_table(table: Curves, seeds: list[int]) -> list[str]:
    """Markdown: mean success over seeds per method and budget (the seeds counted in brackets)."""
    budgets = sorted({d for m in table for s in table[m] for d in table[m][s]})
    lines = [f"| method | {' | '.join(f'{d:g}' for d in budgets)} |", "|---|" + "---:|" * len(budgets)]
    for method in METHODS:
        cells = []
        for demos in budgets:
            values = [table[method][s][demos] for s in seeds if demos in table[method].get(s, {})]
            cells.append(f"{np.mean(values):.3f} ({len(values)})" if values else "-")
        lines.append(f"| {method} | {' | '.join(cells)} |")
    return lines


def main(path: Path) -> None:
    """Prints the success tables, the primary and the secondary outcomes."""
    in_domain, unseen = load(path, IN_DOMAIN), load(path, UNSEEN)
    seeds = sorted(set().union(*(in_domain[m].keys() for m in METHODS if m in in_domain)))
    window = f"{WINDOW[0]:g}-{WINDOW[1]:g} demos per drawer"
    print(f"In-domain success (11 training drawers), mean over seeds {seeds}:")
    print("\n".join(success_table(in_domain, seeds)))
    print(f"\nUnseen success (4 held-out drawers, shared embedding), mean over seeds {seeds}:")
    print("\n".join(success_table(unseen, seeds)))
    print(f"\nPrimary, mean in-domain success over {window}:")
    for method, baseline in PRIMARY:
        print(difference_line(in_domain, method, baseline, seeds))
    print(f"\nSecondary, mean in-domain success over {window}:")
    for method, baseline in SECONDARY:
        print(difference_line(in_domain, method, baseline, seeds))
    print(f"\nSecondary, mean unseen success over {window}:")
    for method, baseline in UNSEEN_PAIRS:
        print(difference_line(unseen, method, baseline, seeds))


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else DEFAULT)
