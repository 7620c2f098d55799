"""need's and uniform's success per training, budget and seed, and run.sh's rule applied per method.

Usage (``lab`` on the path: ``PYTHONPATH=experiments``), from the repository root:
``.venv/bin/python experiments/plateau-dagger-training-dev/table.py outputs/plateau-dagger-training-dev``
(the folder holding one compare folder per training, each with its ``results.csv``). Written on
2026-11-28 with run.sh, before any of its runs. The plain training's runs are
``../beyond-plateau-dev/report/results.csv`` unless the plain check (seed 100 re-run with today's
code) differs from them in any round, as run.sh fixed. The last lines,
``Decision: the best training of <method> is <training>.``, are what the evaluation study reads.
"""

from __future__ import annotations

import csv
import sys
from pathlib import Path

from lab.bc_choice import choice_report

BUDGETS = (33, 45, 63)
SEEDS = (100, 101, 102)
TRAININGS = ("plain", "balanced", "cosine", "plateau")
METHODS = ("need", "uniform")
PLAIN = Path(__file__).resolve().parent.parent / "beyond-plateau-dev" / "report" / "results.csv"

Curves = dict[str, dict[tuple[int, int], float]]


def read_curves(path: Path) -> dict[str, dict[tuple[int, int], float]]:
    """``{method: {(demos per task, seed): mean success}}`` of the DAgger runs in one ``results.csv``."""
    curves: dict[str, dict[tuple[int, int], float]] = {}
    if not path.is_file():
        return curves
    with path.open() as handle:
        for row in csv.DictReader(handle):
            if row["method"] not in METHODS or row["bc"] == "True":
                continue
            budget = round(float(row["demos_per_task_mean"]))
            curves.setdefault(row["method"], {})[(budget, int(row["seed"]))] = float(row["eval_success_mean"])
    return curves


def plain_check(folder: Path, reused: dict[str, Curves]) -> tuple[bool | None, str]:
    """Whether seed 100's plain re-run equals the reused curve in every round (None: not run yet)."""
    check = read_curves(folder / "plain-check" / "results.csv")
    if not all(len([k for k in check.get(m, {}) if k[1] == 100]) == 21 for m in METHODS):
        return None, "plain check: not finished (the plain row is the reused one until it is)"
    differ = [
        f"{m} {budget} demos"
        for m in METHODS
        for (budget, seed), value in check[m].items()
        if reused[m].get((budget, seed)) != value
    ]
    if differ:
        return False, f"plain check: today's code differs from the reused runs at {', '.join(differ)}"
    return True, "plain check: today's code gives the reused curve in every round (seed 100)"


def main() -> None:
    """Prints the tables and each method's decision for the outputs folder given as the argument."""
    folder = Path(sys.argv[1])
    by_training = {t: read_curves(folder / t / "results.csv") for t in TRAININGS if t != "plain"}
    by_training["plain"] = read_curves(PLAIN)
    same, line = plain_check(folder, {m: by_training["plain"].get(m, {}) for m in METHODS})
    print(line)
    for method in METHODS:
        results = {t: by_training[t].get(method, {}) for t in TRAININGS}
        if same is False:  # run.sh: the plain row then needs today's runs on every seed
            results["plain"] = {}
        print(f"\n## {method}\n")
        decision = f"the best training of {method} is {{}}"
        lines = choice_report(
            results, TRAININGS, BUDGETS, SEEDS, label="training", decision=decision, none_word="none"
        )
        print("\n".join(lines))


if __name__ == "__main__":
    main()
