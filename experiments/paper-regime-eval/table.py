"""run.sh's settings and analyses for the paper's regime on evaluation seeds, written before any run.

Two uses (``lab`` on the path: ``PYTHONPATH=experiments``), from the repository root:

- ``table.py --settings outputs/paper-regime-training-dev outputs/paper-regime-pertask-dev`` prints the
  settings run.sh reads (each arm's training, the rounds, BC's budgets, the hardest tasks), all decided
  on the development seeds by the rules in run.sh; exit 1 while the development study has not decided.
- ``table.py outputs/paper-regime-eval`` prints the pre-specified outcomes: the primary (need - uniform
  in mean success over the budgets), the co-primary (demos per task to 0.80), the secondary differences,
  the hardest-task analysis and each arm's passes over each task's frames.
"""

from __future__ import annotations

import csv
import importlib.util
import json
import math
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lab.passes import compare_runs, phase_passes
from lerobot_mtdagger.analysis.results import experiment_rows
from lerobot_mtdagger.analysis.stats import Interval, demos_to_reach, format_difference, paired_difference
from lerobot_mtdagger.datasets.experiment_dir import open_run

ARMS = ("bc", "uniform", "need", "need_raw", "gain")
SEARCHED = ("bc", "uniform", "need")  # need_raw and gain take need's training
TRAININGS = ("plain", "cosine")
DEV_SEEDS = (100, 101)
EVAL_SEEDS = (0, 1, 2)
LEVEL = 0.80
HARDEST = 5
ROUNDS_IF_REACHED, ROUNDS_OTHERWISE = 9, 12
PER_ROUND, INITIAL = 3, 3


def load_training_table():
    """The development study's own ``table.py`` (its rule), loaded from its folder."""
    path = Path(__file__).resolve().parents[1] / "paper-regime-training-dev" / "table.py"
    spec = importlib.util.spec_from_file_location("training_dev_table", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def read_rows(folder: Path) -> list[dict]:
    """Every row under ``folder/<training>-seed<seed>/``, with ``arm`` and ``training``.

    A compare folder's ``results.csv`` when it has one; while its compare is still running (no table
    yet), its runs' own records, from ``outputs/`` or the saved archive: the same rows, including the
    phases of a run not finished yet (an incomplete curve counts for no seed in the analysis); a run
    that has committed no round yet gives none.
    """
    rows = []
    for compare in sorted(path for path in folder.glob("*-seed*") if path.is_dir()):
        training = compare.name.split("-seed")[0]
        table = compare / "results.csv"
        if table.is_file():
            with table.open() as handle:
                found = list(csv.DictReader(handle))
        else:
            found = [row for run in compare_runs(compare) if has_round(run) for row in experiment_rows(run)]
        rows += [table_row(row, training) for row in found]
    return rows


def has_round(run: Path) -> bool:
    """Whether ``run`` has committed a round (a run just started has none, and no row yet)."""
    return bool(open_run(run).committed_rounds())


def table_row(row: dict, training: str) -> dict:
    """One results row (a ``results.csv`` line or ``experiment_rows``'s dict) with the fields used here."""
    per_task = row["eval_success"]
    return {
        **row,
        "arm": "bc" if str(row["bc"]) == "True" else row["method"],
        "training": training,
        "seed": int(row["seed"]),
        "demos": round(float(row["demos_per_task_mean"]), 1),
        "success": float(row["eval_success_mean"]),
        "per_task": json.loads(per_task) if isinstance(per_task, str) else list(per_task),
    }


def settings(dev: Path, check: Path) -> list[str] | None:
    """run.sh's settings from the development study, or None while it has not decided them."""
    table = load_training_table()
    success = table.read_success(dev)
    choice = {}
    for arm in SEARCHED:
        chosen, _ = table.choose(success, arm)
        if chosen is None:
            return None
        choice[arm] = chosen
    choice["need_raw"] = choice["gain"] = choice["need"]
    need_30 = float(np.mean([success[("need", choice["need"], seed, 30)] for seed in DEV_SEEDS]))
    rounds = ROUNDS_IF_REACHED if need_30 >= LEVEL else ROUNDS_OTHERWISE
    budgets = [6, 12, 18, 24, 30] + ([39] if rounds == ROUNDS_OTHERWISE else [])
    names = sed_line(check / "kept.txt", "tasks").split(",")
    bc_30 = [
        row["per_task"]
        for row in read_rows(dev)
        if row["arm"] == "bc"
        and row["training"] == choice["bc"]
        and row["demos"] == 30
        and row["seed"] in DEV_SEEDS
    ]
    if len(bc_30) != len(DEV_SEEDS):
        return None
    hardest = np.argsort(np.mean(bc_30, axis=0), kind="stable")[:HARDEST]
    lines = [f"training {arm}: {choice[arm]}" for arm in ARMS]
    for training in TRAININGS:
        lines.append(f"arms {training}: " + ",".join(arm for arm in ARMS if choice[arm] == training))
    lines += [
        f"need at 30 demos (development, {choice['need']}): {need_30:.3f}",
        f"rounds: {rounds}",
        "bc budgets: " + ",".join(str(b) for b in budgets),
        "hardest tasks: " + ",".join(names[i] for i in hardest),
        "hardest task indices: " + ",".join(str(int(i)) for i in hardest),
    ]
    return lines


def sed_line(path: Path, key: str) -> str:
    """The value of a ``key: value`` line of a text file."""
    for line in path.read_text().splitlines():
        if line.startswith(f"{key}: "):
            return line[len(key) + 2 :]
    raise KeyError(f"{path} has no '{key}:' line")


def curves(rows: list[dict]) -> dict[str, dict[int, list[dict]]]:
    """``{arm: {seed: rows sorted by demos}}``."""
    grouped: dict[str, dict[int, list[dict]]] = defaultdict(lambda: defaultdict(list))
    for row in rows:
        grouped[row["arm"]][row["seed"]].append(row)
    return {
        arm: {s: sorted(r, key=lambda x: x["demos"]) for s, r in seeds.items()}
        for arm, seeds in grouped.items()
    }


def mean_over_budgets(curve: list[dict], budgets: list[float], tasks: list[int] | None = None) -> float:
    """Mean success at ``budgets`` (over ``tasks`` when given); NaN unless every budget was evaluated."""
    at = {row["demos"]: row for row in curve}
    if any(b not in at for b in budgets):
        return math.nan
    if tasks is None:
        return float(np.mean([at[b]["success"] for b in budgets]))
    return float(np.mean([[at[b]["per_task"][t] for t in tasks] for b in budgets]))


def reach(curve: list[dict]) -> tuple[float | None, float]:
    """Demos per task to reach LEVEL (None: never, censored at the returned last budget)."""
    demos = [row["demos"] for row in curve]
    return demos_to_reach(demos, [row["success"] for row in curve], LEVEL), demos[-1]


def paired(name: str, by_seed_a: dict[int, float], by_seed_b: dict[int, float]) -> str:
    """``name: per-seed differences; mean [95% t interval]`` over the seeds both have."""
    seeds = [
        s
        for s in EVAL_SEEDS
        if not math.isnan(by_seed_a.get(s, math.nan)) and not math.isnan(by_seed_b.get(s, math.nan))
    ]
    if len(seeds) < 2:
        return f"{name}: {len(seeds)} seed(s) complete, no interval yet"
    interval: Interval = paired_difference([by_seed_a[s] for s in seeds], [by_seed_b[s] for s in seeds])
    per_seed = " / ".join(f"{by_seed_a[s] - by_seed_b[s]:+.3f}" for s in seeds)
    return f"{name} (seeds {seeds}): {per_seed}; {format_difference(interval)}"


def verdict(interval: Interval | None) -> str:
    """run.sh's rule on the primary interval."""
    if interval is None or math.isnan(interval.low):
        return "not yet decided (fewer than 3 seeds)"
    if interval.low > 0:
        return "reproduced"
    if interval.high < 0:
        return "reversed"
    return "inconclusive"


def analysis(folder: Path) -> list[str]:
    """The pre-specified outcomes, as lines."""
    lines_of = (folder / "settings.txt").read_text().splitlines()
    setting = {line.split(": ", 1)[0]: line.split(": ", 1)[1] for line in lines_of if ": " in line}
    budgets = [float(b) for b in setting["bc budgets"].split(",")]
    names = setting["hardest tasks"].split(",")
    hardest = [int(i) for i in setting["hardest task indices"].split(",")]
    grouped = curves(read_rows(folder))
    means = {
        arm: {s: mean_over_budgets(c, budgets) for s, c in seeds.items()} for arm, seeds in grouped.items()
    }
    hard = {
        arm: {s: mean_over_budgets(c, budgets, hardest) for s, c in seeds.items()}
        for arm, seeds in grouped.items()
    }
    out = [
        "Settings: " + "; ".join(lines_of),
        "",
        "Mean success over budgets " + ", ".join(f"{b:g}" for b in budgets),
    ]
    for arm in ARMS:
        cells = [f"{means.get(arm, {}).get(s, math.nan):.3f}" for s in EVAL_SEEDS]
        out.append(f"  {arm}: seeds {EVAL_SEEDS}: " + " / ".join(cells))
    empty: dict[int, float] = {}
    primary = paired("PRIMARY need - uniform", means.get("need", empty), means.get("uniform", empty))
    seeds = [
        s
        for s in EVAL_SEEDS
        if not math.isnan(means.get("need", {}).get(s, math.nan))
        and not math.isnan(means.get("uniform", {}).get(s, math.nan))
    ]
    interval = None
    if len(seeds) == len(EVAL_SEEDS):
        interval = paired_difference([means["need"][s] for s in seeds], [means["uniform"][s] for s in seeds])
    out += ["", primary, f"Verdict (run.sh's rule): {verdict(interval)}", ""]
    out.append(f"Co-primary: demos per task to reach {LEVEL:.2f} (None: not reached by the last budget)")
    reached = {  # complete curves only: a run still going is not censored
        arm: {s: reach(c) for s, c in seeds_.items() if set(budgets) <= {row["demos"] for row in c}}
        for arm, seeds_ in grouped.items()
    }
    for arm in ARMS:
        cells = []
        for s in EVAL_SEEDS:
            value = reached.get(arm, {}).get(s)
            cells.append(
                "-" if value is None else (f"{value[0]:.1f}" if value[0] is not None else f">{value[1]:g}")
            )
        out.append(f"  {arm}: " + " / ".join(cells))
    for a, b in (("need", "uniform"), ("need", "bc")):
        da = {s: v[0] for s, v in reached.get(a, {}).items() if v[0] is not None}
        db = {s: v[0] for s, v in reached.get(b, {}).items() if v[0] is not None}
        out.append("  " + paired(f"{a} - {b} (demos, seeds where both reach)", da, db))
    out += ["", "Secondary (mean success over the budgets):"]
    for a, b in (("need_raw", "uniform"), ("gain", "uniform"), ("need", "bc"), ("uniform", "bc")):
        out.append("  " + paired(f"{a} - {b}", means.get(a, empty), means.get(b, empty)))
    out += ["", f"Hardest {len(names)} tasks (development BC at 30 demos): {', '.join(names)}"]
    for a, b in (("need", "uniform"), ("need", "bc")):
        out.append("  " + paired(f"{a} - {b} on the hardest tasks", hard.get(a, empty), hard.get(b, empty)))
    return (
        out + ["", "Passes over each task's frames per phase (mean [min-max] over tasks):"] + passes(folder)
    )


def passes(folder: Path) -> list[str]:
    """Each run's passes over each task's frames, phase by phase (from ``outputs/`` or saved records)."""
    lines = []
    for compare in sorted(folder.glob("*-seed*")):
        for run in compare_runs(compare):
            cells = phase_passes(run)
            if cells:
                lines.append(f"  {compare.name}/{run.name}: " + "; ".join(cells))
    return lines


def main(argv: list[str]) -> int:
    """``--settings DEV CHECK`` or ``FOLDER``; see the module's docstring."""
    if argv[:1] == ["--settings"]:
        lines = settings(Path(argv[1]), Path(argv[2]))
        if lines is None:
            print("the development study has not decided every arm's training yet")
            return 1
        print("\n".join(lines))
        return 0
    print("\n".join(analysis(Path(argv[0]))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
