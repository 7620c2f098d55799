"""The paper's figures, from a results table (``results.py``); ``summary.py`` writes them with ``report.md``.

Curves are means over seeds with a 95% t band, BC runs points with 95% error bars. Each a PNG:

1. ``success_vs_demos.png`` / ``success_vs_frames.png``: success against expert demos (or
   expert-labelled frames) per task;
2. ``demos_to_reach.png``: demos per task to reach each success level (seeds that never reach a
   level are counted in the bar label);
3. ``metrics_vs_success.png``: task need (1 - Kalman p) and gain per task against final success;
4. ``hardest_tasks.png``: success on the two hardest tasks;
5. ``kalman_ablation.png``: task need with (``need``) and without (``need_raw``) the Kalman filter;
6. ``time_to_reach.png``: wall time (collection + training + evaluation) to reach each level.
"""

from __future__ import annotations

import math
from collections import defaultdict
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lerobot_mtdagger.analysis.curves import is_bc
from lerobot_mtdagger.analysis.results import PHASE_TIMINGS
from lerobot_mtdagger.analysis.stats import (
    Interval,
    correlation,
    demos_to_reach,
    mean_interval,
)

LEVELS = (0.5, 0.6, 0.7, 0.8)
Row = dict[str, Any]


# -------------------------------------------------------------------------------------------------
# Curves from rows
# -------------------------------------------------------------------------------------------------


def bc_methods(rows: Sequence[Row]) -> list[str]:
    """The methods (labels) of BC runs: ``bc`` first, then its labelled variants."""
    names = {row["method"] for row in rows if is_bc(row)}
    return sorted(names, key=lambda name: (name != "bc", name))


def baselines(rows: Sequence[Row]) -> list[str]:
    """What every other method is compared with: Uniform DAgger and every BC variant."""
    return ["uniform", *bc_methods(rows)]


def runs_by_method(rows: Sequence[Row]) -> dict[str, dict[int, list[Row]]]:
    """Method -> seed -> that seed's rows as one curve (a DAgger run's rounds, or BC's budgets), by demos."""
    grouped: dict[str, dict[int, list[Row]]] = defaultdict(lambda: defaultdict(list))
    for row in rows:
        grouped[row["method"]][row["seed"]].append(row)
    for seeds in grouped.values():
        for seed, curve in seeds.items():
            seeds[seed] = sorted(curve, key=lambda r: (r["demos_per_task_mean"], r["round"]))
    return {method: dict(seeds) for method, seeds in sorted(grouped.items())}


def point_columns(seeds: dict[int, list[Row]]) -> list[list[Row]]:
    """The seeds' rows grouped by point (round, mean demos per task), in order."""
    columns: dict[tuple[int, float], list[Row]] = defaultdict(list)
    for curve in seeds.values():
        for row in curve:
            columns[(row["round"], round(row["demos_per_task_mean"], 6))].append(row)
    return [columns[key] for key in sorted(columns, key=lambda key: (key[1], key[0]))]


def curve_points(seeds: dict[int, list[Row]], x_key: str, y_of=None) -> list[tuple[float, Interval]]:
    """Mean x and the interval of y over seeds, point by point (``point_columns``)."""
    y_of = y_of or (lambda row: row["eval_success_mean"])
    return [
        (float(np.mean([r[x_key] for r in column])), mean_interval([y_of(r) for r in column]))
        for column in point_columns(seeds)
    ]


def seed_reach(curve: Sequence[Row], level: float, x_values) -> float | None:
    """The demos, frames or seconds at which one seed's curve first reaches ``level`` (interpolated)."""
    xs = list(x_values(curve))
    success = [row["eval_success_mean"] for row in curve]
    if all(b > a for a, b in zip(xs, xs[1:], strict=False)):
        return demos_to_reach(xs, success, level)
    reached = [x for x, s in zip(xs, success, strict=True) if s >= level]
    return min(reached) if reached else None


def demos_of(curve: Sequence[Row]) -> list[float]:
    """Mean expert demos per task at each point of a curve."""
    return [row["demos_per_task_mean"] for row in curve]


def frames_of(curve: Sequence[Row]) -> list[float]:
    """Mean expert-labelled frames per task at each point of a curve (the expert's queries)."""
    return [row["expert_frames_per_task_mean"] for row in curve]


def cumulative_seconds(curve: Sequence[Row]) -> list[float]:
    """Wall time spent up to each point of a DAgger curve (BC: each point's own run)."""
    if curve and is_bc(curve[0]):
        return [sum(row[name] for name in PHASE_TIMINGS) for row in curve]
    return list(np.cumsum([sum(row[name] for name in PHASE_TIMINGS) for row in curve]))


# -------------------------------------------------------------------------------------------------
# Figures
# -------------------------------------------------------------------------------------------------


def _pyplot():
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    return plt


def caption(rows: Sequence[Row]) -> str:
    """The figures' and the summary's caption: seeds, interval, evaluation episodes per task."""
    seeds = len({row["seed"] for row in rows})
    episodes = sorted({row["eval_episodes_per_task"] for row in rows})
    return f"mean over {seeds} seeds, 95% t interval; {'/'.join(map(str, episodes))} eval episodes per task"


def plot_success(
    rows: Sequence[Row],
    x_key: str,
    x_label: str,
    path: Path,
    methods=None,
    y_key: str = "eval_success_mean",
    title: str | None = None,
) -> Path:
    """Figure 1 (and 5 with ``methods``): ``y_key`` against demos or frames, one curve per method."""
    rows = [row for row in rows if row.get(y_key) is not None]
    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(7, 4.5))
    bc_names = bc_methods(rows)
    for method, seeds in runs_by_method(rows).items():
        if methods is not None and method not in methods:
            continue
        points = curve_points(seeds, x_key, lambda row: row[y_key])
        x = [p for p, _ in points]
        mean = np.array([i.mean for _, i in points])
        # Success is a fraction: the band is drawn within [0, 1] (a t interval over few seeds is wide).
        low = np.clip([i.low for _, i in points], 0.0, 1.0)
        high = np.clip([i.high for _, i in points], 0.0, 1.0)
        if method in bc_names:
            error = np.nan_to_num(np.vstack([mean - low, high - mean]))
            label = "BC (one round)" if method == "bc" else f"{method} (BC, one round)"
            marker, color = ("s", "black") if method == "bc" else ("D", "dimgray")
            axis.errorbar(x, mean, yerr=error, fmt=marker, capsize=3, label=label, color=color)
        else:
            (line,) = axis.plot(x, mean, marker="o", label=method)
            axis.fill_between(x, low, high, alpha=0.2, color=line.get_color())
    if not axis.lines and not axis.collections:
        wanted = "any method" if methods is None else " or ".join(sorted(methods))
        message = f"no runs of {wanted} in these experiments"
        axis.text(0.5, 0.5, message, ha="center", transform=axis.transAxes)
    axis.set_xlabel(x_label)
    axis.set_ylabel("average evaluation success (fraction of episodes)")
    axis.set_ylim(-0.02, 1.02)
    if title is None:
        title = "Success against expert data" if methods is None else "Task need with and without Kalman"
    axis.set_title(title)
    _legend(axis)
    axis.grid(alpha=0.3)
    figure.text(0.01, 0.01, caption(rows), fontsize=8)
    return _save(figure, path)


def plot_reach(
    rows: Sequence[Row], levels: Sequence[float], path: Path, x_values, x_label: str, title: str
) -> Path:
    """Figures 2 and 6: x needed to reach each level, per method (bars: mean, whiskers: 95%)."""
    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(8, 4.5))
    grouped = runs_by_method(rows)
    width = 0.8 / max(len(grouped), 1)
    for position, (method, seeds) in enumerate(grouped.items()):
        for level_index, level in enumerate(levels):
            reached = [seed_reach(curve, level, x_values) for curve in seeds.values()]
            values = [v for v in reached if v is not None]
            x = level_index + (position - (len(grouped) - 1) / 2) * width
            missing = len(reached) - len(values)
            if values:
                interval = mean_interval(values)
                error = 0.0 if math.isnan(interval.half_width) else interval.half_width
                axis.bar(
                    x,
                    interval.mean,
                    width,
                    yerr=error,
                    capsize=2,
                    color=f"C{position}",
                    label=method if level_index == 0 else None,
                )
            label = f"{len(values)}/{len(reached)}" if missing else ""
            axis.text(x, 0, label or "", ha="center", va="bottom", fontsize=7, rotation=90)
    axis.set_xticks(range(len(levels)), [f"{level:.0%}" for level in levels])
    axis.set_xlabel("average success level (bars marked k/n: only k of n seeds reached it)")
    axis.set_ylabel(x_label)
    axis.set_title(title)
    _legend(axis)
    axis.grid(alpha=0.3, axis="y")
    figure.text(0.01, 0.01, caption(rows), fontsize=8)
    return _save(figure, path)


def plot_metrics(rows: Sequence[Row], path: Path) -> tuple[Path, dict[str, float]]:
    """Figure 3: task need (1 - Kalman p) and gain per task, last scheduled round, vs final success."""
    plt = _pyplot()
    figure, axes = plt.subplots(1, 2, figsize=(10, 4.5))
    coefficients = {}
    for axis, (method, key, label) in zip(
        axes,
        [("need", "kalman_p", "task need 1 - p (Kalman)"), ("gain", "gain", "performance gain")],
        strict=True,
    ):
        x_all, y_all = [], []
        for curve in runs_by_method(rows).get(method, {}).values():
            scheduled = [row for row in curve if row.get(key)]
            if not scheduled:
                continue
            values = np.asarray(scheduled[-1][key], dtype=float)
            x_all += (1.0 - values if key == "kalman_p" else values).tolist()
            y_all += curve[-1]["eval_success"]
        coefficients[method] = correlation(x_all, y_all)
        axis.scatter(x_all, y_all, alpha=0.6)
        axis.set_xlabel(f"{label} per task, last scheduled round")
        axis.set_ylabel("final evaluation success per task")
        axis.set_title(f"{method}: r = {coefficients[method]:.2f} ({len(x_all)} task-seeds)")
        axis.grid(alpha=0.3)
    figure.text(0.01, 0.01, caption(rows), fontsize=8)
    return _save(figure, path), coefficients


def hardest_tasks(rows: Sequence[Row], count: int = 2) -> list[int]:
    """Task indices with the lowest BC success at the largest budget (without BC: final success)."""
    names = bc_methods(rows)
    bc = [row for row in rows if names and row["method"] == names[0]]
    if bc:
        largest = max(row["demos_per_task_mean"] for row in bc)
        pool = [row for row in bc if row["demos_per_task_mean"] == largest]
    else:
        last = max(row["round"] for row in rows)
        pool = [row for row in rows if row["round"] == last]
    success = np.mean([row["eval_success"] for row in pool], axis=0)
    return [int(i) for i in np.argsort(success, kind="stable")[:count]]


def plot_hardest(rows: Sequence[Row], task_names: Sequence[str], path: Path) -> tuple[Path, list[int]]:
    """Figure 4: success curves of every method on the two hardest tasks."""
    plt = _pyplot()
    tasks = hardest_tasks(rows)
    bc_names = bc_methods(rows)
    figure, axes = plt.subplots(1, len(tasks), figsize=(5 * len(tasks), 4.5), squeeze=False)
    for axis, task in zip(axes[0], tasks, strict=True):
        for method, seeds in runs_by_method(rows).items():
            points = curve_points(
                seeds, "demos_per_task_mean", y_of=lambda row, t=task: row["eval_success"][t]
            )
            x = [np.mean([r["demos_per_task"][task] for r in column]) for column in point_columns(seeds)]
            mean = [i.mean for _, i in points]
            style = "s" if method in bc_names else "o-"
            axis.plot(x, mean, style, label=method)
            low, high = [i.low for _, i in points], [i.high for _, i in points]
            if method not in bc_names:
                axis.fill_between(x, low, high, alpha=0.15)
        axis.set_title(f"{task_names[task]}")
        axis.set_xlabel("expert demos of this task")
        axis.set_ylabel("evaluation success on this task")
        axis.set_ylim(-0.02, 1.02)
        axis.grid(alpha=0.3)
        _legend(axis)
    figure.suptitle("The two hardest tasks")
    figure.text(0.01, 0.01, caption(rows), fontsize=8)
    return _save(figure, path), tasks


def _legend(axis) -> None:
    """A legend when something on the axis has a label (a level no seed reached draws nothing)."""
    if axis.get_legend_handles_labels()[0]:
        axis.legend()


def _save(figure, path: Path) -> Path:
    figure.tight_layout(rect=(0, 0.04, 1, 1))
    figure.savefig(path, dpi=110)
    import matplotlib.pyplot as plt

    plt.close(figure)
    return path
