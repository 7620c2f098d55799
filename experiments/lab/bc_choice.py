"""Choosing a BC baseline's training on development seeds, by a rule fixed before the runs.

A BC baseline that loses success when given more of the same expert's data is under-tuned, and a
method that beats it has not shown anything. The studies that pick BC's training (sampling, learning
rate schedule, stopping rule) on development seeds all apply one rule, fixed in their ``run.sh``
before any run: among the trainings whose mean success at the largest budget is not below their mean
at the smallest by more than ``drop_allowed``, take the one with the highest mean over every budget;
if none qualifies, the highest mean, and say so. The rule applies only once every (training, budget,
seed) run has finished.

The records are the ones ``scripts/save_run_records.sh`` saves:
``<folder>/<training>/bc-<budget>demos-seed<seed>/policies/round-000/training.json``, or the same
runs' folders compacted into ``<folder>/<training>/runs-records.tar.gz`` (``scripts/compact_records.sh``).
"""

from __future__ import annotations

import json
import re
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.saved_records import ARCHIVE_NAME, unpack

BC_RUN_NAME = re.compile(r"bc-(\d+)demos-seed(\d+)")
DROP_ALLOWED = 0.01

Results = Mapping[str, Mapping[tuple[int, int], float]]


def read_bc_records(folder: Path) -> dict[str, dict[tuple[int, int], float]]:
    """Mean evaluation success of every saved BC run, by training, then (budget, seed).

    Args:
        folder: Holds one folder per training, each with the records of its BC runs (folders, or
            compacted into its ``runs-records.tar.gz``).

    Returns:
        ``{training: {(budget, seed): success}}``; runs whose only phase has no record yet are absent.
    """
    results: dict[str, dict[tuple[int, int], float]] = {}
    found = [(path, path.parents[3].name) for path in folder.glob("*/*/policies/round-000/training.json")]
    for archive in folder.glob(f"*/{ARCHIVE_NAME}"):  # a training's runs compacted into one archive
        found += [
            (path, archive.parent.name) for path in unpack(archive).glob("*/policies/round-000/training.json")
        ]
    for path, training in sorted(found, key=lambda item: (item[1], item[0].parents[2].name)):
        match = BC_RUN_NAME.fullmatch(path.parents[2].name)
        if match is None:
            continue
        budget, seed = int(match.group(1)), int(match.group(2))
        success = json.loads(path.read_text())["eval"]["mean"]
        results.setdefault(training, {})[(budget, seed)] = float(success)
    return results


def success_table(
    results: Results, budgets: Sequence[int], seeds: Sequence[int], label: str = "training"
) -> list[str]:
    """A Markdown table: one row per training and budget, success per seed and the mean of those done."""
    lines = [f"| {label} | demos/task | " + " | ".join(f"seed {s}" for s in seeds) + " | mean |"]
    lines.append("|---|---:|" + "---:|" * (len(seeds) + 1))
    for training, runs in sorted(results.items()):
        for budget in budgets:
            values = [runs.get((budget, seed)) for seed in seeds]
            done = [v for v in values if v is not None]
            cells = " | ".join("-" if v is None else f"{v:.3f}" for v in values)
            mean = f"{np.mean(done):.3f}" if done else "-"
            lines.append(f"| {training} | {budget} | {cells} | {mean} |")
    return lines


@dataclass(frozen=True)
class BCChoice:
    """The rule's outcome.

    Attributes:
        chosen: The training the rule picks, or ``None`` while some run has not finished.
        qualified: Whether ``chosen`` met the no-drop condition (``False``: none did, the highest mean
            was taken).
        lines: One line per training (its mean over the budgets, its change from the smallest budget
            to the largest, whether it qualifies), or the reason no choice is made yet.
    """

    chosen: str | None
    qualified: bool
    lines: tuple[str, ...]


def choose_bc_training(
    results: Results,
    trainings: Sequence[str],
    budgets: Sequence[int],
    seeds: Sequence[int],
    drop_allowed: float = DROP_ALLOWED,
) -> BCChoice:
    """Applies the rule to the runs of ``trainings`` at every budget and seed.

    Args:
        results: ``{training: {(budget, seed): success}}`` (:func:`read_bc_records`).
        trainings: The candidates the study fixed; all must be complete for a choice.
        budgets: Demos per task, the smallest and the largest deciding the no-drop condition.
        seeds: The development seeds.
        drop_allowed: How far the mean at the largest budget may fall below the smallest's.

    Returns:
        The choice, with the lines that justify it.
    """
    missing = [
        f"{training} {budget} demos seed {seed}"
        for training in trainings
        for budget in budgets
        for seed in seeds
        if (budget, seed) not in results.get(training, {})
    ]
    if missing:
        runs = len(budgets) * len(seeds)
        reason = f"not yet: {len(missing)} runs unfinished (every training needs all {runs})"
        return BCChoice(None, False, (reason,))
    low, high = min(budgets), max(budgets)
    lines, qualified, means = [], [], {}
    for training in trainings:
        runs = results[training]
        by_budget = {b: float(np.mean([runs[(b, s)] for s in seeds])) for b in budgets}
        means[training] = float(np.mean(list(by_budget.values())))
        change = by_budget[high] - by_budget[low]
        ok = -change <= drop_allowed
        qualified += [training] if ok else []
        verdict = "qualifies" if ok else "drops: does not qualify"
        lines.append(
            f"{training}: mean over budgets {means[training]:.3f}; {high} - {low} demos {change:+.3f} "
            f"({verdict})"
        )
    pool = qualified or list(trainings)
    chosen = max(pool, key=lambda training: means[training])
    return BCChoice(chosen, bool(qualified), tuple(lines))


def choice_report(
    results: Results,
    trainings: Sequence[str],
    budgets: Sequence[int],
    seeds: Sequence[int],
    *,
    label: str,
    decision: str,
    none_word: str,
) -> list[str]:
    """The table, the rule's lines and the study's ``Decision:`` line, as a study's ``table.txt`` holds them.

    Args:
        results: ``{training: {(budget, seed): success}}`` (:func:`read_bc_records`).
        trainings: The candidates the study fixed.
        budgets: Demos per task.
        seeds: The development seeds.
        label: The table's first column (``training``, ``sampling``).
        decision: The decision's wording, ``{}`` standing for the chosen training.
        none_word: ``none`` or ``neither``, for the note when no training qualified.
    """
    lines = success_table(results, budgets, seeds, label)
    choice = choose_bc_training(results, trainings, budgets, seeds)
    if choice.chosen is None:
        return [*lines, "", f"Decision: {choice.lines[0]}."]
    note = ""
    if not choice.qualified:
        note = f" ({none_word} qualified: the highest mean; BC's training needs more study)"
    return [*lines, "", *choice.lines, f"Decision: {decision.format(choice.chosen)}{note}."]
