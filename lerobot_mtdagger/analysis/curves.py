"""Learning curves: evaluation success against expert demonstrations, method by method, from points.

Runs of one method with different seeds are grouped; a point is the mean and sample standard
deviation over seeds at the same round (the same demos per task for every seed of a method).
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.markdown import markdown_table


@dataclass
class CurvePoint:
    """Evaluation success of one method after one round, over seeds."""

    method: str
    round: int
    demos_per_task: float
    mean: float
    std: float
    seeds: int


RunPoints = tuple[str, int, list[tuple[int, float, float]]]
"""``(method, seed, [(round, mean demos per task, mean eval success), ...])`` of one run."""


def curve_name(method: str, is_bc: bool, demos_per_task: float) -> str:
    """BC at several budgets is one group per budget (a point each), named with its budget."""
    return f"{method} ({demos_per_task:g} demos/task)" if is_bc else method


def is_bc(row: Mapping[str, Any]) -> bool:
    """Whether a results row comes from a one-round BC run (under any label)."""
    return bool(row.get("bc", row["method"] == "bc"))


def curves_from_rows(rows: Sequence[Mapping]) -> list[CurvePoint]:
    """The learning curves of a saved results table's rows (ValueError as ``average_runs``)."""
    runs: dict[tuple[str, int], list[tuple[int, float, float]]] = defaultdict(list)
    for row in rows:
        name = curve_name(row["method"], is_bc(row), float(row["demos_per_task_mean"]))
        point = (int(row["round"]), float(row["demos_per_task_mean"]), float(row["eval_success_mean"]))
        runs[(name, int(row["seed"]))].append(point)
    return average_runs([(name, seed, sorted(points)) for (name, seed), points in runs.items()])


def average_runs(runs: Sequence[RunPoints]) -> list[CurvePoint]:
    """Averages each method's runs over seeds, round by round (ValueError on a repeated seed or no point)."""
    grouped: dict[str, dict[int, list[tuple[int, float, float]]]] = defaultdict(dict)
    for method, seed, points in runs:
        if seed in grouped[method]:
            raise UserError(f"Two {method} experiments with seed {seed}; give each run its own seed.")
        grouped[method][seed] = points
    curves = []
    for method, seeds in sorted(grouped.items()):
        by_round: dict[int, list[tuple[float, float]]] = defaultdict(list)
        for points in seeds.values():
            for round_index, demos, success in points:
                by_round[round_index].append((demos, success))
        for round_index, values in sorted(by_round.items()):
            demos = float(np.mean([d for d, _ in values]))
            successes = [s for _, s in values]
            std = float(np.std(successes, ddof=1)) if len(successes) > 1 else math.nan
            curves.append(
                CurvePoint(method, round_index, demos, float(np.mean(successes)), std, len(successes))
            )
    if not curves:
        raise UserError(
            f"None of the {len(runs)} experiment(s) has an evaluated phase (they ran with "
            "--rollout.eval_episodes=0?): evaluate their policies with `lerobot-mtdagger eval` or rerun them "
            "with --rollout.eval_episodes > 0."
        )
    return curves


def curves_table(curves: Sequence[CurvePoint]) -> str:
    """The curves as a markdown table (one row per method and round)."""
    header = ["method", "round", "expert demos per task", "eval success (mean)", "std over seeds", "seeds"]
    rows = [
        [
            point.method,
            point.round,
            f"{point.demos_per_task:.1f}",
            f"{point.mean:.3f}",
            "n/a" if math.isnan(point.std) else f"{point.std:.3f}",
            point.seeds,
        ]
        for point in curves
    ]
    return markdown_table(header, rows, "lrrrrr")
