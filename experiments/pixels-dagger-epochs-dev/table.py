"""The outcomes and the rule of ``run.sh`` (pixel DAgger with fixed steps or steps that grow with the data).

From the repository root, once both arms are done and ``save_records.sh`` has run, ``report.sh``
(each arm's report from its records, then this script into ``table.txt``).

Reads each arm's ``results.csv`` and ``../pixels-bc-dev``'s (balanced BC at 60 demos per task).
"""

from __future__ import annotations

import csv
import json
import sys
from pathlib import Path

import numpy as np

from lab.paired import paired_line

STUDY = Path("experiments/pixels-dagger-epochs-dev")
BC_RESULTS = Path("experiments/pixels-bc-dev/report/results.csv")
ARMS = ("epochs", "fixed")
HARD = ("push-v3", "pick-place-v3", "peg-insert-side-v3")
LAST = 60.0
SWITCH = 0.03
NEAR_BC = 0.02

Curves = dict[int, dict[float, list[float]]]  # seed -> demos per task -> per-task success


def load(results: Path, method: str) -> tuple[Curves, list[str]]:
    """Per-task success by seed and demos per task of ``method``'s rows, and the task names."""
    tasks = json.loads((results.parent / "results_meta.json").read_text())["task_names"]
    curves: Curves = {}
    with results.open() as handle:
        for row in csv.DictReader(handle):
            if row["method"] == method:
                curves.setdefault(int(row["seed"]), {})[float(row["demos_per_task_mean"])] = json.loads(
                    row["eval_success"]
                )
    return curves, tasks


def success(per_task: list[float], tasks: list[str], only: tuple[str, ...] | None = None) -> float:
    """Mean success over every task, or over the tasks named in ``only``."""
    chosen = [s for s, name in zip(per_task, tasks, strict=True) if only is None or name in only]
    return float(np.mean(chosen))


def pairs(
    left: Curves, right: Curves, tasks: list[str], only: tuple[str, ...] | None = None
) -> list[tuple[float, float]]:
    """(left, right) success at LAST demos per task on every seed both hold."""
    seeds = sorted(s for s in left if LAST in left[s] and s in right and LAST in right[s])
    return [(success(left[s][LAST], tasks, only), success(right[s][LAST], tasks, only)) for s in seeds]


def decision(arms: dict[str, Curves], bc: Curves, tasks: list[str]) -> str:
    """The rule of ``run.sh``, on means over the seeds both arms hold."""
    both = pairs(arms["epochs"], arms["fixed"], tasks)
    if not both:
        return "Decision: none yet (no seed has both arms at phase 5)."
    gain = float(np.mean([e - f for e, f in both]))
    seeds = sorted(s for s in arms["epochs"] if LAST in arms["epochs"][s])
    start = float(np.mean([success(arms["epochs"][s][min(arms["epochs"][s])], tasks) for s in seeds]))
    end = float(np.mean([success(arms["epochs"][s][LAST], tasks) for s in seeds]))
    if gain >= SWITCH and end >= start:
        verdict = "the preset's DAgger phases switch to epochs (10 passes)"
        against_bc = pairs(arms["epochs"], bc, tasks)
        bc_gap = float(np.mean([e - b for e, b in against_bc])) if against_bc else float("nan")
        rerun = "proposed" if bc_gap >= -NEAR_BC else "not proposed"
        verdict += f"; epochs - BC at 60 {bc_gap:+.3f}: a pixels-eval rerun is {rerun}"
    else:
        verdict = "the preset stays fixed"
    return (
        f"Decision: {verdict} (epochs - fixed at 60 {gain:+.3f}, needs >= +{SWITCH}; "
        f"epochs phase 0 {start:.3f}, phase 5 {end:.3f})."
    )


def main(study: Path = STUDY, bc_results: Path = BC_RESULTS) -> None:
    """Prints every phase's mean, the primary and secondary outcomes and the decision."""
    arms: dict[str, Curves] = {}
    tasks: list[str] = []
    for arm in ARMS:
        arms[arm], tasks = load(study / "report" / arm / "results.csv", "uniform")
    bc, bc_tasks = load(bc_results, "bc-balanced")
    if bc_tasks != tasks:
        raise SystemExit(f"{bc_results} lists other tasks than this study: {bc_tasks}")
    budgets = sorted({d for curves in arms.values() for seed in curves.values() for d in seed})
    print(f"| arm | {' | '.join(f'{d:g}' for d in budgets)} |  (mean success over seeds; seeds in brackets)")
    print("|---|" + "---:|" * len(budgets))
    for arm in ARMS:
        cells = []
        for demos in budgets:
            values = [success(c[demos], tasks) for c in arms[arm].values() if demos in c]
            cells.append(f"{np.mean(values):.3f} ({len(values)})" if values else "-")
        print(f"| {arm} | {' | '.join(cells)} |")
    print(f"\nAt {LAST:g} demos per task, paired over seeds:")
    print(paired_line("primary: epochs - fixed", pairs(arms["epochs"], arms["fixed"], tasks)))
    print(paired_line("hard tasks: epochs - fixed", pairs(arms["epochs"], arms["fixed"], tasks, HARD)))
    for arm in ARMS:
        print(paired_line(f"{arm} - balanced BC", pairs(arms[arm], bc, tasks)))
        print(paired_line(f"hard tasks: {arm} - balanced BC", pairs(arms[arm], bc, tasks, HARD)))
    print("\n" + decision(arms, bc, tasks))


if __name__ == "__main__":
    main(*(Path(arg) for arg in sys.argv[1:3]))
