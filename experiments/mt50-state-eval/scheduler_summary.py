"""Two summaries of the MT50 study that the report does not make, both fixed by one rule per seed.

1. **Success over the budgets where the methods part** (9 to 33 demos per task; 3 and 6 are shared
   by every DAgger method): each seed's mean success over those 9 budgets, paired over seeds between
   a method and a baseline. One number per seed, so the 9 budgets are not 9 chances to find a
   difference.
2. **The gain on the hardest tasks, chosen without bias**: the report picks the hardest tasks by
   BC's success at its largest budget (two of 50 tasks, and regression to the mean favours any method
   against that BC). Here the hardest fifth of the tasks (10 of 50) are those with the lowest success
   after round 0, the 3-demo policy that every method of the seed shares, so the choice favours no
   method. Final success (33 demos per task) minus Uniform DAgger's, averaged over those tasks and
   over the other 40, paired over seeds.

Reads saved tables (by default the MT50 study's per-seed tables and its BC-balanced runs in the
final ``report/``; any folders written by ``report`` given as arguments instead, such as the MT10
study's ``report/``) and prints markdown. From the repository root:

    .venv/bin/python experiments/mt50-state-eval/scheduler_summary.py \
        > experiments/mt50-state-eval/scheduler_summary.txt
    .venv/bin/python experiments/mt50-state-eval/scheduler_summary.py experiments/mt10-state-eval/report \
        > experiments/mt50-state-eval/scheduler_summary_mt10.txt
"""

from __future__ import annotations

import sys
from collections.abc import Sequence
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.results import SavedTable, merge_tables, read_results
from lerobot_mtdagger.analysis.stats import Interval, format_difference, mean_interval, paired_difference

HERE = Path("experiments/mt50-state-eval")
MAIN_TABLES = tuple(HERE / "seeds" / f"seed{seed}" for seed in (0, 1, 2))
METHODS = ("bc", "bc-balanced", "uniform", "need", "need_raw", "gain")
PARTED_BUDGETS = (9, 12, 15, 18, 21, 24, 27, 30, 33)
FINAL_BUDGET = 33
HARDEST_SHARE = 0.2
PAIRS = (
    ("need", "uniform"),
    ("gain", "uniform"),
    ("need_raw", "uniform"),
    ("need", "need_raw"),
    ("need", "bc"),
    ("gain", "bc"),
    ("uniform", "bc"),
    ("need", "bc-balanced"),
    ("gain", "bc-balanced"),
    ("bc-balanced", "bc"),
)


def saved_table(folders: Sequence[Path]) -> SavedTable:
    """The rows of ``folders`` joined; by default the MT50 main comparison and its BC-balanced runs."""
    if folders:
        return merge_tables([read_results(folder) for folder in folders])
    main = merge_tables([read_results(folder) for folder in MAIN_TABLES])
    final = read_results(HERE / "report")
    balanced = [row for row in final.rows if row["method"] == "bc-balanced"]
    return SavedTable(main.rows + balanced, main.task_names, final.unfinished, main.configs, main.source)


def per_task_success(table: SavedTable) -> dict[tuple[str, int, int], np.ndarray]:
    """``(method, seed, demos per task) -> per-task eval success`` of every row."""
    return {
        (row["method"], int(row["seed"]), round(row["demos_per_task_mean"])): np.asarray(
            row["eval_success"], dtype=np.float64
        )
        for row in table.rows
    }


def seeds_of(success: dict) -> list[int]:
    """Every seed of the table."""
    return sorted({seed for _, seed, _ in success})


def present(success: dict, method: str) -> bool:
    """Whether ``method`` has every parted budget of every seed."""
    return all((method, seed, budget) in success for seed in seeds_of(success) for budget in PARTED_BUDGETS)


def parted_mean(success: dict, method: str, seed: int) -> float:
    """One seed's average success, averaged over ``PARTED_BUDGETS``."""
    return float(np.mean([success[(method, seed, budget)].mean() for budget in PARTED_BUDGETS]))


def hardest_tasks(success: dict, seed: int) -> np.ndarray:
    """Indices of the hardest fifth of the tasks by the shared round-0 (3-demo) success of ``seed``."""
    round0 = success[("uniform", seed, 3)]
    count = round(HARDEST_SHARE * round0.size)
    return np.argsort(round0, kind="stable")[:count]


def split_difference(success: dict, method: str, baseline: str) -> tuple[Interval, Interval]:
    """Final success of ``method`` minus ``baseline`` on the hardest tasks and on the others."""
    hard, other = [], []
    for seed in seeds_of(success):
        difference = success[(method, seed, FINAL_BUDGET)] - success[(baseline, seed, FINAL_BUDGET)]
        mask = np.zeros(difference.size, dtype=bool)
        mask[hardest_tasks(success, seed)] = True
        hard.append(float(difference[mask].mean()))
        other.append(float(difference[~mask].mean()))
    return mean_interval(hard), mean_interval(other)


def parted_lines(success: dict) -> list[str]:
    """Markdown table of summary 1."""
    lines = [
        f"## Mean success over {PARTED_BUDGETS[0]}-{PARTED_BUDGETS[-1]} demos per task, paired over seeds",
        "",
        "| method | seeds " + " / ".join(str(s) for s in seeds_of(success)) + " | mean [95% t] |",
        "|---|---|---|",
    ]
    for method in (method for method in METHODS if present(success, method)):
        values = [parted_mean(success, method, seed) for seed in seeds_of(success)]
        interval = mean_interval(values)
        per_seed = " / ".join(f"{value:.3f}" for value in values)
        bounds = f"[{interval.low:.3f}, {interval.high:.3f}]"
        lines.append(f"| {method} | {per_seed} | {interval.mean:.3f} {bounds} |")
    lines += ["", "| method - baseline | difference [95% t] |", "|---|---|"]
    for method, baseline in PAIRS:
        if not (present(success, method) and present(success, baseline)):
            continue
        first = [parted_mean(success, method, seed) for seed in seeds_of(success)]
        second = [parted_mean(success, baseline, seed) for seed in seeds_of(success)]
        lines.append(f"| {method} - {baseline} | {format_difference(paired_difference(first, second))} |")
    return lines


def hardest_lines(success: dict, task_names: Sequence[str]) -> list[str]:
    """Markdown table of summary 2."""
    lines = [
        f"## Final success ({FINAL_BUDGET} demos per task) on the hardest {HARDEST_SHARE:.0%} of tasks "
        "by round-0 success, against the others",
        "",
    ]
    for seed in seeds_of(success):
        names = ", ".join(task_names[k].removesuffix("-v3") for k in hardest_tasks(success, seed))
        lines.append(f"- seed {seed}: {names}")
    lines += ["", "| method - baseline | hardest tasks | other tasks |", "|---|---|---|"]
    for method, baseline in PAIRS[:4]:
        hard, other = split_difference(success, method, baseline)
        lines.append(f"| {method} - {baseline} | {format_difference(hard)} | {format_difference(other)} |")
    return lines


def main(folders: Sequence[str]) -> None:
    """Print both summaries as markdown, of ``folders`` or of the MT50 study."""
    table = saved_table([Path(folder) for folder in folders])
    success = per_task_success(table)
    lines = [*parted_lines(success), "", *hardest_lines(success, table.task_names)]
    print("\n".join(lines))


if __name__ == "__main__":
    main(sys.argv[1:])
