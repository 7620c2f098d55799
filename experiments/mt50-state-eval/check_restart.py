"""Does the restarted MT50 study reproduce the seed-0 numbers of the lost first attempt?

The first attempt's run folders were lost with its machine; its seed-0 curves survive only as the
table in ``README.md`` (average evaluation success at each budget, three decimals), copied below.
The restart runs the same frozen code with the same settings and seeds, so every point it has made
must equal the lost one. Reads the saved table of the interim or final report; prints each point
that both have, and exits 1 if any differs. From the repository root, after ``snapshot.py``:

    .venv/bin/python experiments/mt50-state-eval/check_restart.py
"""

from __future__ import annotations

import sys
from pathlib import Path

from lerobot_mtdagger.analysis.results import read_results

REPORT = Path("experiments/mt50-state-eval/report")
BUDGETS = (3, 6, 9, 12, 15, 18, 21, 24, 27, 30, 33)
LOST_SEED0 = {
    "bc": (0.677, 0.826, 0.848, 0.910, 0.924, 0.928, 0.942, 0.916, 0.925, 0.939, 0.904),
    "uniform": (0.677, 0.807, 0.808, 0.799, 0.822, 0.867, 0.877, 0.888, 0.897, 0.908, 0.914),
    "need": (0.677, 0.807, 0.788, 0.826, 0.883, 0.892, 0.912, 0.915, 0.924, 0.942, 0.911),
    "need_raw": (0.677, 0.807, 0.775, 0.820, 0.871, 0.884, 0.919, 0.909, 0.891, 0.918, 0.914),
    "gain": (0.677, 0.807, 0.809, 0.801, 0.851, 0.885, 0.903, 0.919, 0.925, 0.937, 0.929),
}
"""Seed 0 of the first attempt, from README.md: method -> success at each of ``BUDGETS``."""


def restarted_seed0(report: Path) -> dict[tuple[str, int], float]:
    """``(method, demos per task) -> eval success`` of the restart's seed-0 rows."""
    return {
        (row["method"], round(row["demos_per_task_mean"])): row["eval_success_mean"]
        for row in read_results(report).rows
        if row["seed"] == 0 and row["method"] in LOST_SEED0
    }


def main() -> int:
    """Prints lost vs restarted success for every point both have; 1 if any differs at 3 decimals."""
    restarted = restarted_seed0(REPORT)
    differing = 0
    compared = 0
    for method, successes in LOST_SEED0.items():
        for budget, lost in zip(BUDGETS, successes, strict=True):
            new = restarted.get((method, budget))
            if new is None:
                continue
            compared += 1
            same = round(new, 3) == lost
            differing += not same
            verdict = "=" if same else "DIFFERS"
            print(f"{method:<9} {budget:>2} demos/task  lost {lost:.3f}  restarted {new:.3f}  {verdict}")
    total = sum(len(s) for s in LOST_SEED0.values())
    print(f"{compared} of {total} seed-0 points made again; {differing} differ.")
    return 1 if differing else 0


if __name__ == "__main__":
    sys.exit(main())
