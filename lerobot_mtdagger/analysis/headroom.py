"""Headroom: how much any split of the same expert demonstrations could beat an even split.

Given each task's learning curve, the best split of ``N * b`` demos over ``N`` tasks is a knapsack
solved exactly by dynamic programming over integer demos; the headroom at ``b`` demos per task is its
mean success minus the even split's. Curves pool the success rates at the same demos (weighted by
episodes), are made non-decreasing by isotonic regression and interpolated linearly, never extended
past the measured range. With several seeds the in-sample headroom is optimistic; the honest one
chooses the split on the other seeds and scores it on the held-out seed (a t interval over seeds).
Pure numpy.
"""

from __future__ import annotations

import json
import math
from collections import defaultdict
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lerobot_mtdagger.analysis.stats import mean_interval
from lerobot_mtdagger.learning_curve import isotonic
from lerobot_mtdagger.utils.errors import UserError


@dataclass(frozen=True)
class TaskPoint:
    """One measured point of one task's learning curve.

    Attributes:
        demos: Expert demonstrations of this task the policy was trained on.
        success: Evaluation success rate of the task, in [0, 1].
        episodes: Evaluation episodes behind ``success`` (its weight).
    """

    task: int
    seed: int
    demos: int
    success: float
    episodes: int


@dataclass(frozen=True)
class LearningCurves:
    """Each task's success against its own expert demos, on a common grid of integer demos.

    Attributes:
        low: Smallest demos per task every curve covers; ``high``: the largest.
        success: Success of task i at ``low + j`` demos, shape (num_tasks, high - low + 1).
        measured: The measured demos of each task's curve (the knots of its interpolation).
        seeds: The seeds the curves pool.
    """

    task_names: tuple[str, ...]
    low: int
    high: int
    success: np.ndarray
    measured: tuple[tuple[int, ...], ...]
    seeds: tuple[int, ...]

    @property
    def num_tasks(self) -> int:
        """Number of tasks."""
        return len(self.task_names)

    def at(self, demos: np.ndarray) -> np.ndarray:
        """Success of each task at its own demos (integers within [low, high]), shape (num_tasks,)."""
        index = np.asarray(demos, dtype=np.int64) - self.low
        return self.success[np.arange(self.num_tasks), index]


def fit_curves(points: Sequence[TaskPoint], task_names: Sequence[str]) -> LearningCurves:
    """Estimates every task's curve from measured points, on the integer demos every task covers.

    Raises:
        UserError: If a task lacks two measured budgets, a point is out of range, or the tasks'
            measured ranges overlap in fewer than two demos.
    """
    by_task = _points_by_task(points, len(task_names), task_names)
    knots, fitted = [], []
    for task, task_points in enumerate(by_task):
        demos, values = _pooled_isotonic(task_points)
        if demos.size < 2:
            raise UserError(
                f"Task {task_names[task]!r} was measured at {demos.size} budget(s) ({demos.tolist()}): a "
                "learning curve needs two or more; add runs at other demos per task (a BC grid or DAgger "
                "phases)."
            )
        knots.append(demos)
        fitted.append(values)
    low, high = max(int(k[0]) for k in knots), min(int(k[-1]) for k in knots)
    if high <= low:
        raise UserError(
            f"The tasks' measured ranges share no stretch of demos (common range [{low}, {high}]): measure "
            "every task over the same budgets."
        )
    grid = np.arange(low, high + 1)
    success = np.stack([np.interp(grid, k, v) for k, v in zip(knots, fitted, strict=True)])
    seeds = tuple(sorted({point.seed for point in points}))
    return LearningCurves(
        tuple(task_names), low, high, success, tuple(tuple(int(d) for d in k) for k in knots), seeds
    )


def _points_by_task(
    points: Sequence[TaskPoint], num_tasks: int, task_names: Sequence[str]
) -> list[list[TaskPoint]]:
    """Groups points by task, checking each one."""
    by_task: list[list[TaskPoint]] = [[] for _ in range(num_tasks)]
    for point in points:
        if not 0 <= point.task < num_tasks:
            raise UserError(f"A curve point names task {point.task}, outside the {num_tasks} tasks.")
        if not (math.isfinite(point.success) and 0.0 <= point.success <= 1.0) or point.episodes < 1:
            raise UserError(
                f"A curve point of task {task_names[point.task]!r} has success {point.success} over "
                f"{point.episodes} episode(s): a success rate in [0, 1] over at least one episode is needed."
            )
        by_task[point.task].append(point)
    missing = [task_names[i] for i, task_points in enumerate(by_task) if not task_points]
    if missing:
        raise UserError(f"No measured point for task(s) {missing}: every task needs its own curve.")
    return by_task


def _pooled_isotonic(task_points: Sequence[TaskPoint]) -> tuple[np.ndarray, np.ndarray]:
    """One task's measured budgets and its isotonic success there (points pooled by demos)."""
    successes: dict[int, float] = defaultdict(float)
    episodes: dict[int, int] = defaultdict(int)
    for point in task_points:
        successes[point.demos] += point.success * point.episodes
        episodes[point.demos] += point.episodes
    demos = np.array(sorted(successes), dtype=np.int64)
    weights = np.array([episodes[d] for d in demos], dtype=np.float64)
    means = np.array([successes[d] / episodes[d] for d in demos])
    return demos, isotonic(means, weights)


# --------------------------------------------------------------------------------------------------
# The best split: exact dynamic programming over integer demos
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class BestSplits:
    """The best split of every total budget the curves cover.

    Attributes:
        totals: Total demos, from ``num_tasks * low`` to ``num_tasks * high``.
        value: Mean success over tasks of the best split of each total, shape (len(totals),).
        choice: Demos of task i in the best split of each total, shape (num_tasks, len(totals)).
    """

    curves: LearningCurves
    totals: np.ndarray
    value: np.ndarray
    choice: np.ndarray

    def split(self, total: int) -> np.ndarray:
        """Demos per task of the best split of ``total`` demos."""
        return self.choice[:, self._index(total)]

    def _index(self, total: int) -> int:
        index = int(total) - int(self.totals[0])
        if not 0 <= index < self.totals.size:
            raise UserError(
                f"A total of {total} demos is outside what the curves cover ({int(self.totals[0])} to "
                f"{int(self.totals[-1])}, i.e. {self.curves.low}-{self.curves.high} demos per task)."
            )
        return index

    def demos_to_match(self, level: float) -> float | None:
        """Fewest demos per task (total / tasks) whose best split reaches a mean success ``level``."""
        reached = np.flatnonzero(self.value >= level - 1e-12)
        return None if reached.size == 0 else float(self.totals[reached[0]]) / self.curves.num_tasks


def best_splits(curves: LearningCurves) -> BestSplits:
    """Solves the knapsack of every total at once: max mean success with each task in [low, high].

    Dynamic programming over tasks, ``best_k(T) = max_n best_{k-1}(T - n) + f_k(n)``, in
    ``num_tasks * width`` numpy calls (about 10 ms for 43 tasks over 25 budgets).
    """
    width = curves.high - curves.low + 1
    num_tasks = curves.num_tasks
    best = curves.success[0].copy()  # over extra demos 0..width-1 above num_tasks * low
    arg = np.zeros((num_tasks, num_tasks * (width - 1) + 1), dtype=np.int64)
    arg[0, :width] = np.arange(width)
    for task in range(1, num_tasks):
        size = best.size + width - 1
        candidates = np.full((width, size), -np.inf)
        for extra in range(width):
            candidates[extra, extra : extra + best.size] = best + curves.success[task, extra]
        arg[task, :size] = np.argmax(candidates, axis=0)
        best = candidates.max(axis=0)
    choice = _backtrack(arg, best.size, width)
    totals = num_tasks * curves.low + np.arange(best.size)
    return BestSplits(curves, totals, best / num_tasks, choice + curves.low)


def _backtrack(arg: np.ndarray, size: int, width: int) -> np.ndarray:
    """Each task's extra demos in the best split of every total, from the DP's argmax table."""
    num_tasks = arg.shape[0]
    choice = np.zeros((num_tasks, size), dtype=np.int64)
    remaining = np.arange(size)
    for task in range(num_tasks - 1, -1, -1):
        extra = arg[task, remaining]
        choice[task] = extra
        remaining = remaining - extra
    if np.any(remaining != 0) or np.any(choice >= width):
        raise AssertionError("the best-split backtrack did not spend every total exactly")
    return choice


# --------------------------------------------------------------------------------------------------
# Headroom at each budget, in sample and held out
# --------------------------------------------------------------------------------------------------


@dataclass(frozen=True)
class Headroom:
    """What the best split of ``demos_per_task * num_tasks`` demos gains over the even split.

    Attributes:
        even: Mean success of the even split; ``best``: of the best split; ``gain``: ``best - even``.
        demos_to_match: Demos per task the best split needs to match ``even`` (None: not in range).
    """

    demos_per_task: int
    even: float
    best: float
    gain: float
    demos_to_match: float | None
    split: tuple[int, ...]

    @property
    def saving(self) -> float | None:
        """Demos per task the best split saves against the even split."""
        return None if self.demos_to_match is None else self.demos_per_task - self.demos_to_match


def headroom_at(splits: BestSplits, demos_per_task: int) -> Headroom:
    """The headroom at an even budget, from the best splits of the same curves (in sample)."""
    curves = splits.curves
    _check_budget(curves, demos_per_task)
    even = float(curves.at(np.full(curves.num_tasks, demos_per_task)).mean())
    total = demos_per_task * curves.num_tasks
    best = float(splits.value[splits._index(total)])
    return Headroom(
        demos_per_task,
        even,
        best,
        best - even,
        splits.demos_to_match(even),
        tuple(int(n) for n in splits.split(total)),
    )


def _check_budget(curves: LearningCurves, demos_per_task: int) -> None:
    if not curves.low <= demos_per_task <= curves.high:
        raise UserError(
            f"{demos_per_task} demos per task is outside the measured range {curves.low}-{curves.high}: "
            "headroom is computed only where every task's curve was measured (no extrapolation)."
        )


@dataclass(frozen=True)
class HeldOutHeadroom:
    """The honest headroom at one budget: split chosen on the other seeds, scored on each held-out one.

    Attributes:
        per_seed: ``(seed, best-split success - even success)`` on each held-out seed.
        mean: Mean over held-out seeds; ``low``, ``high``: its 95% t interval (NaN with one seed).
    """

    demos_per_task: int
    per_seed: tuple[tuple[int, float], ...]
    mean: float
    low: float
    high: float


def held_out_headroom(
    points: Sequence[TaskPoint], task_names: Sequence[str], budgets: Sequence[int]
) -> list[HeldOutHeadroom]:
    """Leave-one-seed-out headroom at each of ``budgets`` (demos per task) that every fold covers.

    Raises:
        UserError: With fewer than two seeds, or as ``fit_curves`` for any fold.
    """
    seeds = sorted({point.seed for point in points})
    if len(seeds) < 2:
        raise UserError(f"A held-out headroom needs two or more seeds; the records hold {seeds}.")
    gains: dict[int, list[tuple[int, float]]] = defaultdict(list)
    for seed in seeds:
        own = fit_curves([p for p in points if p.seed == seed], task_names)
        others = fit_curves([p for p in points if p.seed != seed], task_names)
        splits = best_splits(others)
        for budget in budgets:
            if not (others.low <= budget <= others.high and own.low <= budget <= own.high):
                continue
            split = np.clip(splits.split(budget * others.num_tasks), own.low, own.high)
            even = own.at(np.full(own.num_tasks, budget)).mean()
            gains[budget].append((seed, float(own.at(split).mean() - even)))
    results = []
    for budget in budgets:
        if len(gains[budget]) != len(seeds):
            continue
        interval = mean_interval([gain for _, gain in gains[budget]])
        results.append(
            HeldOutHeadroom(budget, tuple(gains[budget]), interval.mean, interval.low, interval.high)
        )
    return results


# --------------------------------------------------------------------------------------------------
# Points from the rows of a results table
# --------------------------------------------------------------------------------------------------

BC_CURVES = "bc"
"""Curve source: one-round BC runs, plus round 0 of every DAgger run (BC on its initial demos)."""

ALL_CURVES = "all"
"""Curve source: every evaluated phase of every run (DAgger phases add on-policy data)."""


def points_from_rows(rows: Sequence[dict], source: str = BC_CURVES) -> list[TaskPoint]:
    """One curve point per task, evaluated row and seed of a results table's rows.

    ``source``: ``"bc"`` (BC runs and DAgger round 0), ``"all"``, or one method's name.
    """
    points = []
    for row in rows:
        if not _row_in_source(row, source) or row.get("eval_success") in (None, ""):
            continue
        demos, success = _as_list(row["demos_per_task"]), _as_list(row["eval_success"])
        episodes = int(row.get("eval_episodes_per_task") or 0)
        for task, (n, rate) in enumerate(zip(demos, success, strict=True)):
            if rate is not None and episodes > 0:
                points.append(TaskPoint(task, int(row["seed"]), int(round(float(n))), float(rate), episodes))
    return points


def _row_in_source(row: dict, source: str) -> bool:
    is_bc = bool(row.get("bc", row["method"] == "bc"))
    if source == BC_CURVES:
        return is_bc or int(row["round"]) == 0
    return source == ALL_CURVES or row["method"] == source


def _as_list(value: str | Iterable[Any]) -> list:
    """A list column, stored as a list or as its JSON text in a CSV."""
    if isinstance(value, str):
        return json.loads(value)
    return list(value)
