"""need and uniform with their chosen trainings against the best BC on the evaluation seeds 0-4.

Written on 2026-11-28 with run.sh, before any of its runs. Two uses (``lab`` on the path:
``PYTHONPATH=experiments``), from the repository root:

- ``table.py --trainings FILE`` reads ``../plateau-dagger-training-dev/table.py``'s output (FILE) and
  prints each method's chosen training, one ``<method>: <training>`` line each (what run.sh runs);
  exit 1, saying why, while either method has no ``Decision:`` line or that study's plain check has
  not finished.
- ``table.py [FOLDER]`` prints success per seed at 33, 45 and 63 demos per task, the primary outcome
  and the secondary ones fixed in run.sh. With FOLDER (``outputs/plateau-dagger-eval``) it reads
  ``FOLDER/decision.txt`` and each compare's ``results.csv`` (``FOLDER/<training>-seed<seed>/``);
  without, the saved records here (``save_records.sh``): ``records/decision.txt`` and
  ``records/<training>-seed<seed>/runs-records.tar.gz``. A method whose training is plain is read from
  ``../beyond-plateau-eval/report/results.csv``; the best BC (cosine) from
  ``../beyond-plateau-best-bc/records/cosine/``. Every outcome says "not finished" until all 5 seeds
  have their whole window.
"""

from __future__ import annotations

import csv
import json
import math
import re
import sys
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np

from lab.bc_choice import read_bc_records
from lab.paired import paired_line
from lerobot_mtdagger.analysis.saved_records import ARCHIVE_NAME, unpack
from lerobot_mtdagger.analysis.stats import paired_difference

HERE = Path(__file__).resolve().parent
PLAIN_RESULTS = HERE.parent / "beyond-plateau-eval" / "report" / "results.csv"
BEST_BC_RECORDS = HERE.parent / "beyond-plateau-best-bc" / "records"
BEST_BC = "cosine"  # ../beyond-plateau-best-bc/table.txt: "The best BC (../bc-past-plateau-dev): cosine."
DECISION_FILE = "decision.txt"
METHODS = ("need", "uniform")
TRAININGS = ("plain", "balanced", "cosine", "plateau")
SEEDS = (0, 1, 2, 3, 4)
BUDGETS = (33, 45, 63)
DAGGER_WINDOW = tuple(range(45, 64, 3))  # the phases of rounds 14-20: 45, 48, ..., 63 demos per task
BC_WINDOW = (45, 63)  # BC's budgets in the window
DECISION = re.compile(r"^Decision: the best training of ([a-z_]+) is ([a-z]+)\b.*$", re.MULTILINE)
PLAIN_CHECK_PENDING = "plain check: not finished"
DAGGER_RUN = re.compile(r"([a-z_]+)-seed(\d+)")
NOT_FINISHED = "not finished"

Curve = dict[int, float]  # demos per task -> mean success
Curves = dict[int, Curve]  # seed -> curve


def decision_problem(text: str) -> str | None:
    """Why the development study's output is not yet a decision (``None``: it is one).

    Args:
        text: What ``../plateau-dagger-training-dev/table.py`` printed.
    """
    decided = dict(DECISION.findall(text))
    undecided = [method for method in METHODS if method not in decided]
    if undecided:
        return f"no 'Decision: the best training of ...' line for {' and '.join(undecided)}"
    unknown = [f"{m}: {decided[m]}" for m in METHODS if decided[m] not in TRAININGS]
    if unknown:
        return f"unknown training(s) {', '.join(unknown)} (expected one of {', '.join(TRAININGS)})"
    if any(line.startswith(PLAIN_CHECK_PENDING) for line in text.splitlines()):
        return "its plain check has not finished, so its plain rows (and the decision) may still change"
    return None


def chosen_trainings(text: str) -> dict[str, str]:
    """``{method: training}`` as the development study decided.

    Raises:
        ValueError: If ``text`` holds no final decision (:func:`decision_problem` says why).
    """
    problem = decision_problem(text)
    if problem is not None:
        raise ValueError(problem)
    decided = dict(DECISION.findall(text))
    return {method: decided[method] for method in METHODS}


def read_results_csv(path: Path, methods: Sequence[str]) -> dict[str, Curves]:
    """``{method: {seed: {demos per task: success}}}``: the DAgger runs of ``methods`` in a results table."""
    curves: dict[str, Curves] = {}
    if not path.is_file():
        return curves
    with path.open() as handle:
        for row in csv.DictReader(handle):
            if row["method"] not in methods or row["bc"] == "True":
                continue
            demos = round(float(row["demos_per_task_mean"]))
            seeds = curves.setdefault(row["method"], {})
            seeds.setdefault(int(row["seed"]), {})[demos] = float(row["eval_success_mean"])
    return curves


def read_archive(archive: Path, methods: Sequence[str]) -> dict[str, Curves]:
    """The same as :func:`read_results_csv`, from the phases' ``training.json`` in a runs' records archive."""
    curves: dict[str, Curves] = {}
    for record in sorted(unpack(archive).glob("*/policies/round-*/training.json")):
        match = DAGGER_RUN.fullmatch(record.parents[2].name)
        if match is None or match.group(1) not in methods:
            continue
        phase = json.loads(record.read_text())
        demos = round(float(np.mean(phase["demos_per_task"])))
        seeds = curves.setdefault(match.group(1), {})
        seeds.setdefault(int(match.group(2)), {})[demos] = float(phase["eval"]["mean"])
    return curves


def merge(into: dict[str, Curves], more: Mapping[str, Curves]) -> None:
    """Adds ``more``'s curves to ``into`` (a seed in both: ``more``'s points are added to its curve)."""
    for method, seeds in more.items():
        for seed, curve in seeds.items():
            into.setdefault(method, {}).setdefault(seed, {}).update(curve)


def study_curves(trainings: Mapping[str, str], folder: Path | None, records: Path) -> dict[str, Curves]:
    """This study's runs of each method whose training is not plain.

    Args:
        trainings: ``{method: training}``.
        folder: The study's outputs folder (its compares' ``results.csv``), or ``None`` for ``records``.
        records: The saved records (one ``<training>-seed<seed>/runs-records.tar.gz`` per compare).
    """
    curves: dict[str, Curves] = {}
    for training in sorted(set(trainings.values()) - {"plain"}):
        methods = [m for m in METHODS if trainings[m] == training]
        if folder is not None:
            for path in sorted(folder.glob(f"{training}-seed*/results.csv")):
                merge(curves, read_results_csv(path, methods))
        else:
            for archive in sorted(records.glob(f"{training}-seed*/{ARCHIVE_NAME}")):
                merge(curves, read_archive(archive, methods))
    return curves


def best_bc_curves(records: Path) -> Curves:
    """The best BC's success by seed and budget, from ``../beyond-plateau-best-bc``'s records."""
    curves: Curves = {}
    for (budget, seed), success in read_bc_records(records).get(BEST_BC, {}).items():
        curves.setdefault(seed, {})[budget] = success
    return curves


def window_mean(curve: Curve, points: Sequence[int]) -> float:
    """Mean success over ``points`` (demos per task); NaN unless every one of them was evaluated."""
    if any(point not in curve for point in points):
        return math.nan
    return float(np.mean([curve[point] for point in points]))


def success_rows(name: str, curves: Curves) -> list[str]:
    """Table rows of one arm: success per seed at each budget; the mean once every seed has it."""
    rows = []
    for budget in BUDGETS:
        values = [curves.get(seed, {}).get(budget) for seed in SEEDS]
        cells = " | ".join("-" if v is None else f"{v:.3f}" for v in values)
        mean = NOT_FINISHED if None in values else f"{np.mean(values):.3f}"
        rows.append(f"| {name} | {budget} | {cells} | {mean} |")
    return rows


def outcome(
    name: str, first: Sequence[float], second: Sequence[float]
) -> tuple[str, tuple[float, float] | None]:
    """``paired_line`` over all the seeds, or "not finished" (naming the seeds) while one is missing.

    Returns:
        The line, and the interval's ``(low, high)`` (``None`` when not finished).
    """
    missing = [s for s, a, b in zip(SEEDS, first, second, strict=True) if math.isnan(a) or math.isnan(b)]
    if missing:
        return (
            f"{name}: {NOT_FINISHED} (seed(s) {', '.join(map(str, missing))} without the whole window)",
            None,
        )
    interval = paired_difference(first, second)
    return paired_line(name, list(zip(first, second, strict=True))), (interval.low, interval.high)


def reading(bounds: tuple[float, float] | None) -> str:
    """run.sh's reading of the primary interval."""
    if bounds is None:
        return f"Reading (run.sh): {NOT_FINISHED}"
    low, high = bounds
    if low > 0:
        return "Reading (run.sh): need is ahead of the best BC (the interval is above 0)"
    if high < 0:
        return "Reading (run.sh): need is behind the best BC (the interval is below 0)"
    return "Reading (run.sh): no difference resolved (the interval holds 0)"


def report(
    decision_text: str, study: Mapping[str, Curves], plain: Mapping[str, Curves], best_bc: Curves
) -> list[str]:
    """The tables and the outcomes, as lines.

    Args:
        decision_text: The development study's output that run.sh saved (``decision.txt``).
        study: This study's runs (:func:`study_curves`).
        plain: ``../beyond-plateau-eval``'s need and uniform runs.
        best_bc: The best BC's runs (:func:`best_bc_curves`).
    """
    trainings = chosen_trainings(decision_text)
    arms = {m: (plain if trainings[m] == "plain" else study).get(m, {}) for m in METHODS}
    label = {m: f"{m}({trainings[m]})" for m in METHODS}
    lines = [line for line in decision_text.splitlines() if line.startswith("Decision: ")]
    for method in METHODS:
        source = (
            "../beyond-plateau-eval's runs, not repeated" if trainings[method] == "plain" else "this study"
        )
        lines.append(f"{method}: {trainings[method]} ({source})")
    lines += [f"best BC: {BEST_BC} (../beyond-plateau-best-bc)", ""]
    lines.append("| arm | demos/task | " + " | ".join(f"seed {s}" for s in SEEDS) + " | mean |")
    lines.append("|---|---:|" + "---:|" * (len(SEEDS) + 1))
    for method in METHODS:
        lines += success_rows(label[method], arms[method])
    lines += success_rows(f"best BC ({BEST_BC})", best_bc)
    window = {m: [window_mean(arms[m].get(s, {}), DAGGER_WINDOW) for s in SEEDS] for m in METHODS}
    bc = [window_mean(best_bc.get(s, {}), BC_WINDOW) for s in SEEDS]
    over = "mean over 45-63 demos per task"
    primary, bounds = outcome(
        f"primary (fixed in run.sh before any run): {label['need']} - best BC, {over}", window["need"], bc
    )
    uniform_bc, _ = outcome(f"secondary: {label['uniform']} - best BC, {over}", window["uniform"], bc)
    need_uniform, _ = outcome(
        f"secondary: {label['need']} - {label['uniform']}, {over}", window["need"], window["uniform"]
    )
    return [*lines, "", primary, reading(bounds), uniform_bc, need_uniform]


def main(argv: Sequence[str]) -> int:
    """``--trainings FILE`` or ``[FOLDER]``; see the module's docstring."""
    if argv[:1] == ["--trainings"]:
        try:
            trainings = chosen_trainings(Path(argv[1]).read_text())
        except ValueError as error:
            print(f"{argv[1]}: no final decision of ../plateau-dagger-training-dev: {error}", file=sys.stderr)
            return 1
        print("\n".join(f"{method}: {training}" for method, training in trainings.items()))
        return 0
    folder = Path(argv[0]) if argv else None
    records = HERE / "records"
    decision_file = (folder if folder is not None else records) / DECISION_FILE
    if not decision_file.is_file():
        print(f"No decision yet: {decision_file} does not exist (run.sh writes it once decided).")
        return 0
    text = decision_file.read_text()
    study = study_curves(chosen_trainings(text), folder, records)
    plain = read_results_csv(PLAIN_RESULTS, METHODS)
    print("\n".join(report(text, study, plain, best_bc_curves(BEST_BC_RECORDS))))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
