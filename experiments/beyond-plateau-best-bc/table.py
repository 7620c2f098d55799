"""The best BC on the evaluation seeds, and need - best BC past the plateau (the secondary outcome).

Usage, from the repository root: (``lab`` on the path: ``PYTHONPATH=experiments``)
``.venv/bin/python experiments/beyond-plateau-best-bc/table.py``
(``save_records.sh`` writes its output to ``table.txt``). It reads:

- the decision of ``../bc-past-plateau-dev/table.txt`` (which training is the best BC);
- need's and plain BC's success from ``../beyond-plateau-eval/report/results.csv`` (the primary
  outcome's runs);
- the best BC's runs from ``records/<training>/`` (``save_records.sh``); for plain BC, the primary's.

It prints BC's success at 33, 45 and 63 demos per task per seed (best and plain), the best BC's change
from 33 to 63, and the paired differences over 45-63 demos per task fixed in ``run.sh``: need - best
BC (the secondary outcome) and best BC - plain BC.
"""

from __future__ import annotations

import csv
import math
import re
from collections import defaultdict
from pathlib import Path

import numpy as np

from lab.bc_choice import read_bc_records
from lab.paired import paired_line

HERE = Path("experiments/beyond-plateau-best-bc")
DECISION_FILE = Path("experiments/bc-past-plateau-dev/table.txt")
PRIMARY_RESULTS = Path("experiments/beyond-plateau-eval/report/results.csv")
SEEDS = (0, 1, 2, 3, 4)
BUDGETS = (33, 45, 63)
WINDOW = (45, 63)
DECISION = re.compile(r"^Decision: the best BC is ([a-z]+)", re.MULTILINE)

Curve = dict[float, float]


def best_training(decision_file: Path) -> str | None:
    """The training ``../bc-past-plateau-dev`` chose, or ``None`` before it has decided."""
    if not decision_file.is_file():
        return None
    match = DECISION.search(decision_file.read_text())
    return match.group(1) if match else None


def primary_curves(path: Path) -> dict[str, dict[int, Curve]]:
    """Evaluation success by method, seed and demos per task, from the primary outcome's table."""
    curves: dict[str, dict[int, Curve]] = defaultdict(lambda: defaultdict(dict))
    with path.open() as handle:
        for row in csv.DictReader(handle):
            demos = float(row["demos_per_task_mean"])
            curves[row["method"]][int(row["seed"])][demos] = float(row["eval_success_mean"])
    return curves


def records_curves(folder: Path, training: str) -> dict[int, Curve]:
    """One training's success by seed and budget, from the saved records (``folder/<training>/``)."""
    curves: dict[int, Curve] = defaultdict(dict)
    for (budget, seed), success in read_bc_records(folder).get(training, {}).items():
        curves[seed][float(budget)] = success
    return curves


def window_mean(curve: Curve) -> float:
    """Mean success over the points with ``WINDOW[0] <= demos <= WINDOW[1]`` (NaN if none yet)."""
    points = [s for d, s in curve.items() if WINDOW[0] <= d <= WINDOW[1]]
    return float(np.mean(points)) if points else math.nan


def bc_window_mean(curve: Curve) -> float:
    """BC's mean over its budgets in the window, NaN until every one of them has finished."""
    if not all(float(budget) in curve for budget in BUDGETS if WINDOW[0] <= budget <= WINDOW[1]):
        return math.nan
    return window_mean(curve)


def bc_rows(name: str, curves: dict[int, Curve]) -> list[str]:
    """Table rows of one BC: success per seed at each budget, and the mean of the seeds done."""
    rows = []
    for budget in BUDGETS:
        values = [curves.get(seed, {}).get(float(budget), math.nan) for seed in SEEDS]
        cells = " | ".join("-" if math.isnan(v) else f"{v:.3f}" for v in values)
        mean = "-" if all(math.isnan(v) for v in values) else f"{np.nanmean(values):.3f}"
        rows.append(f"| {name} | {budget} | {cells} | {mean} |")
    return rows


def change_line(curves: dict[int, Curve]) -> str:
    """The best BC's success at 63 minus at 33 demos per task, per seed with both."""
    changes = [
        curves[seed][63.0] - curves[seed][33.0] for seed in SEEDS if {33.0, 63.0} <= set(curves.get(seed, {}))
    ]
    if not changes:
        return "best BC, 63 - 33 demos: no seed has both yet"
    per_seed = " / ".join(f"{c:+.3f}" for c in changes)
    return f"best BC, 63 - 33 demos: {per_seed} (falls on {sum(c < 0 for c in changes)} of {len(changes)})"


def main() -> None:
    """Prints the tables and the paired differences."""
    training = best_training(DECISION_FILE)
    if training is None:
        print(f"No best BC yet: {DECISION_FILE} holds no decision (finish ../bc-past-plateau-dev).")
        return
    primary = primary_curves(PRIMARY_RESULTS)
    plain = primary["bc"]
    best = plain if training == "plain" else records_curves(HERE / "records", training)
    header = "| BC | demos/task | " + " | ".join(f"seed {s}" for s in SEEDS) + " | mean |"
    lines = [f"The best BC (../bc-past-plateau-dev): {training}.", "", header]
    lines.append("|---|---:|" + "---:|" * (len(SEEDS) + 1))
    lines += bc_rows(f"best ({training})", best) + bc_rows("plain", plain)
    lines += ["", change_line(best), ""]
    window = f"mean over {WINDOW[0]}-{WINDOW[1]} demos"
    need = primary["need"]
    pairs = [(window_mean(need[s]), bc_window_mean(best.get(s, {}))) for s in SEEDS]
    lines.append(paired_line(f"need - best BC (secondary), {window}", pairs))
    pairs = [(bc_window_mean(best.get(s, {})), bc_window_mean(plain[s])) for s in SEEDS]
    lines.append(paired_line(f"best BC - plain BC, {window}", pairs))
    print("\n".join(lines))


if __name__ == "__main__":
    main()
