"""The paper's figures and a markdown summary, from a results table (``results.py``).

Every curve is the mean over seeds with a 95% t confidence band (``stats.mean_interval``); BC runs
are points (one per data budget) with 95% error bars. Figures, each a PNG in the report folder:

1. ``success_vs_demos.png``: average evaluation success against expert demos per task;
   ``success_vs_frames.png``: the same against expert-labelled frames per task (expert queries);
2. ``demos_to_reach.png``: demos per task needed to reach each success level (interpolated per
   seed; seeds that never reach a level are counted in the bar label, never dropped silently);
3. ``metrics_vs_success.png``: the task-need estimate (1 - Kalman p) and the performance gain per
   task after the last scheduled round, against the final evaluated success, with Pearson's r;
4. ``hardest_tasks.png``: success curves on the two hardest tasks (lowest BC success at the largest
   budget; lowest final success over all runs when there is no BC);
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

from lerobot_mtdagger.studies.report import is_bc
from lerobot_mtdagger.studies.results import PHASE_TIMINGS
from lerobot_mtdagger.studies.stats import (
    Interval,
    correlation,
    demos_to_reach,
    format_difference,
    mean_interval,
    paired_difference,
)
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.markdown import markdown_table

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
    """Method -> seed -> that seed's rows as one curve, ordered by demos.

    A DAgger run is one curve (its rounds); BC runs of one seed at several budgets form one curve
    (one point per budget).
    """
    grouped: dict[str, dict[int, list[Row]]] = defaultdict(lambda: defaultdict(list))
    for row in rows:
        grouped[row["method"]][row["seed"]].append(row)
    for seeds in grouped.values():
        for seed, curve in seeds.items():
            seeds[seed] = sorted(curve, key=lambda r: (r["demos_per_task_mean"], r["round"]))
    return {method: dict(seeds) for method, seeds in sorted(grouped.items())}


def point_columns(seeds: dict[int, list[Row]]) -> list[list[Row]]:
    """The seeds' rows grouped point by point: one column per (round, mean demos per task), in order.

    Every seed of a finished method has the same points (``results.check_comparable``); a run still
    being written, or BC run at fewer budgets for one seed, has fewer, and its columns hold fewer
    seeds.
    """
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
    """The demos, frames or seconds at which one seed's curve first reaches ``level``.

    Interpolated along the curve when x increases along it; otherwise (the run times of BC runs at
    several budgets) the smallest x among the points that reach the level.
    """
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


def _caption(rows: Sequence[Row]) -> str:
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
    """Figure 1 (and 5 with ``methods``): success against demos or frames, one curve per method.

    ``y_key="unseen_success_mean"`` draws the success on the unseen tasks instead (rows without it
    are left out).
    """
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
    figure.text(0.01, 0.01, _caption(rows), fontsize=8)
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
    figure.text(0.01, 0.01, _caption(rows), fontsize=8)
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
    figure.text(0.01, 0.01, _caption(rows), fontsize=8)
    return _save(figure, path), coefficients


def hardest_tasks(rows: Sequence[Row], count: int = 2) -> list[int]:
    """Task indices with the lowest BC success at the largest budget (else lowest final success).

    BC is the run labelled ``bc`` where there is one, else any BC variant.
    """
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
    figure.text(0.01, 0.01, _caption(rows), fontsize=8)
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


# -------------------------------------------------------------------------------------------------
# Summary
# -------------------------------------------------------------------------------------------------


def seed_pairs(
    grouped: dict[str, dict[int, list[Row]]], method: str, baseline: str, budget: float
) -> list[tuple[Row, Row]]:
    """The (method, baseline) rows at ``budget`` demos per task, one pair per seed both ran it."""
    pairs = []
    for seed in sorted(set(grouped[method]) & set(grouped[baseline])):
        a = [r for r in grouped[method][seed] if r["demos_per_task_mean"] == budget]
        b = [r for r in grouped[baseline][seed] if r["demos_per_task_mean"] == budget]
        if a and b:
            pairs.append((a[0], b[0]))
    return pairs


def paired_rows(rows: Sequence[Row], method: str, baseline: str) -> list[tuple[float, Interval]]:
    """Paired differences (method - baseline) of success over the seeds both ran, at every common budget."""
    grouped = runs_by_method(rows)
    if method not in grouped or baseline not in grouped:
        return []
    comparisons = []
    for budget in sorted(_budgets(grouped[method])):
        pairs = seed_pairs(grouped, method, baseline, budget)
        if pairs:
            first = [a["eval_success_mean"] for a, _ in pairs]
            second = [b["eval_success_mean"] for _, b in pairs]
            comparisons.append((budget, paired_difference(first, second)))
    return comparisons


def demos_ratio(
    rows: Sequence[Row], method: str, baseline: str, level: float
) -> tuple[float | None, int, int]:
    """Mean over paired seeds of demos(method) / demos(baseline) to reach ``level``; pairs; seeds."""
    grouped = runs_by_method(rows)
    seeds = sorted(set(grouped.get(method, {})) & set(grouped.get(baseline, {})))
    ratios = []
    for seed in seeds:
        a = seed_reach(grouped[method][seed], level, demos_of)
        b = seed_reach(grouped[baseline][seed], level, demos_of)
        if a is not None and b is not None:
            ratios.append(a / b)
    return (float(np.mean(ratios)) if ratios else None), len(ratios), len(seeds)


def comparison_pairs(rows: Sequence[Row]) -> list[tuple[str, str]]:
    """The (method, baseline) pairs of the summary.

    Every method against every baseline (Uniform DAgger and each BC variant), Uniform DAgger against
    each BC variant, each labelled BC variant against ``bc``, and task need with the Kalman filter
    against task need without it.
    """
    bases = baselines(rows)
    bc_names = bc_methods(rows)
    methods = [m for m in runs_by_method(rows) if m not in bases]
    pairs = [(m, b) for m in methods for b in bases] + [("uniform", b) for b in bc_names]
    pairs += [(variant, "bc") for variant in bc_names if variant != "bc" and "bc" in bc_names]
    if "need" in methods and "need_raw" in methods:  # the Kalman filter's own effect
        pairs.append(("need", "need_raw"))
    return pairs


def reach_lines(rows: Sequence[Row], levels: Sequence[float]) -> list[str]:
    """Markdown: expert demos and expert-labelled frames per task each method needed to reach each level."""
    lines = ["## Expert data needed to reach a level", ""]
    lines += [
        "Per task, at the first crossing of each seed's curve (interpolated; BC: along its budgets), mean "
        "over the seeds that reached the level with its 95% t interval; k/n: seeds that reached it.",
        "",
    ]
    table = []
    for method, seeds in runs_by_method(rows).items():
        for level in levels:
            demos = [seed_reach(curve, level, demos_of) for curve in seeds.values()]
            frames = [seed_reach(curve, level, frames_of) for curve in seeds.values()]
            reached = [(d, f) for d, f in zip(demos, frames, strict=True) if d is not None and f is not None]
            cells = ["never", "never"]
            if reached:
                demo_interval = mean_interval([d for d, _ in reached])
                frame_interval = mean_interval([f for _, f in reached])
                cells = [_format_amount(demo_interval, "{:.1f}"), _format_amount(frame_interval, "{:.0f}")]
            table.append([method, f"{level:.0%}", *cells, f"{len(reached)}/{len(demos)}"])
    header = ["method", "level", "expert demos per task", "expert-labelled frames per task", "seeds"]
    return [*lines, markdown_table(header, table, "lrrrr"), ""]


def _format_amount(interval: Interval, pattern: str) -> str:
    if math.isnan(interval.low):
        return pattern.format(interval.mean)
    return (
        f"{pattern.format(interval.mean)} [{pattern.format(interval.low)}, {pattern.format(interval.high)}]"
    )


def task_gap_lines(rows: Sequence[Row], hardest: Sequence[int]) -> list[str]:
    """Markdown: paired differences of final per-task success on the hardest tasks and on the rest."""
    lines = ["## The hardest tasks against the others", ""]
    lines += [
        "Paired over seeds at the largest budget both methods ran: success minus the baseline's, "
        "averaged over the hardest tasks and over the other tasks, 95% t interval. The hardest "
        "tasks are chosen by BC's own success at its largest budget, so a difference against that "
        "BC on them is biased in the method's favour (regression to the mean); against Uniform "
        "DAgger it is not.",
        "",
    ]
    task_count = len(rows[0]["eval_success"]) if rows else 0
    if task_count <= len(hardest):
        return lines[:2] + [f"Not shown: with {task_count} task(s), no task is left besides the hardest.", ""]
    grouped = runs_by_method(rows)
    table = []
    for method, baseline in comparison_pairs(rows):
        if method not in grouped or baseline not in grouped:
            continue
        common = _budgets(grouped[method]) & _budgets(grouped[baseline])
        if not common:
            continue
        budget = max(common)
        hard, other = [], []
        for first, second in seed_pairs(grouped, method, baseline, budget):
            difference = np.subtract(first["eval_success"], second["eval_success"])
            hard.append(float(difference[list(hardest)].mean()))
            other.append(float(np.delete(difference, list(hardest)).mean()))
        if hard:
            differences = [format_difference(mean_interval(hard)), format_difference(mean_interval(other))]
            table.append([method, baseline, f"{budget:.1f}", *differences])
    header = ["method", "baseline", "demos per task", "hardest tasks", "other tasks"]
    return [*lines, markdown_table(header, table, "llrll"), ""]


def _budgets(seeds: dict[int, list[Row]]) -> set[float]:
    return {row["demos_per_task_mean"] for curve in seeds.values() for row in curve}


def stability_lines(rows: Sequence[Row]) -> list[str]:
    """Markdown: how much each DAgger method's success varies over seeds and from round to round."""
    lines = ["## Stability", ""]
    lines += [
        "Per DAgger method: the standard deviation of average success over seeds, averaged over its "
        "rounds; the mean absolute change of a seed's success from one round to the next; the "
        "share of those changes that are drops.",
        "",
    ]
    table = []
    for method, seeds in runs_by_method(rows).items():
        curves = [[row["eval_success_mean"] for row in curve] for curve in seeds.values()]
        if any(is_bc(curve[0]) for curve in seeds.values()) or len(curves) < 2:
            continue
        length = min(len(curve) for curve in curves)
        spread = float(np.mean([np.std([c[k] for c in curves], ddof=1) for k in range(length)]))
        changes = np.concatenate([np.diff(curve) for curve in curves])
        drops = float(np.mean(changes < 0)) if changes.size else math.nan
        mean_change = float(np.mean(np.abs(changes))) if changes.size else math.nan
        table.append([method, f"{spread:.3f}", f"{mean_change:.3f}", f"{drops:.0%}"])
    header = ["method", "std over seeds (mean over rounds)", "round-to-round change", "drops"]
    return [*lines, markdown_table(header, table, "lrrr"), ""]


def cost_lines(rows: Sequence[Row]) -> list[str]:
    """Markdown: the wall time each method's runs took (collect + write + load + train + eval)."""
    lines = ["## What the runs cost", ""]
    lines += [
        "Wall time of the committed phases (collect + write + load + train + eval; start-up not "
        "counted), from each phase's record. A BC run is one budget of one seed.",
        "",
    ]
    table = []
    for method in runs_by_method(rows):
        method_rows = [row for row in rows if row["method"] == method]
        seconds = sum(sum(row[name] for name in PHASE_TIMINGS) for row in method_rows)
        runs = len({row["experiment"] for row in method_rows})
        table.append([method, runs, f"{seconds / runs:.0f}", f"{seconds / 60:.1f}"])
    header = ["method", "runs", "phase time per run, mean (s)", "all runs (min)"]
    return [*lines, markdown_table(header, table, "lrrr"), ""]


def unseen_lines(rows: Sequence[Row]) -> list[str]:
    """Markdown: the paper's in-domain / unseen table, per method at each point (none without unseen tasks).

    In-domain: the training tasks; unseen: the suite's held-out tasks (the drawers a policy has no
    task index for), evaluated after every phase and never given to the scheduler. Progress is the
    0-3 score (touch the handle, pull, open). Mean over seeds with a 95% t interval.
    """
    if not any(row.get("unseen_success_mean") is not None for row in rows):
        return []
    lines = ["## In-domain and unseen tasks", ""]
    lines += [
        "Mean over seeds (95% t interval) after each phase; unseen = held-out tasks, acted on with the "
        "policy's shared task embedding. Progress: 0-3.",
        "",
    ]

    def cell(column: list[Row], key: str) -> str:
        values = [row[key] for row in column if row.get(key) is not None]
        if not values:
            return "n/a"
        interval = mean_interval(values)
        if math.isnan(interval.low):
            return f"{interval.mean:.3f}"
        return f"{interval.mean:.3f} [{interval.low:.3f}, {interval.high:.3f}]"

    table = []
    keys = ("eval_success_mean", "unseen_success_mean", "eval_progress_mean", "unseen_progress_mean")
    for method, seeds in runs_by_method(rows).items():
        for column in point_columns(seeds):
            demos = float(np.mean([row["demos_per_task_mean"] for row in column]))
            table.append([method, f"{demos:.1f}", *(cell(column, key) for key in keys)])
    header = ["method", "demos per task", "in-domain success", "unseen success", "in-domain progress"]
    return [*lines, markdown_table([*header, "unseen progress"], table, "lrllll"), ""]


def interim_lines(unfinished: Sequence[str]) -> list[str]:
    """The interim warning of a report with unfinished runs (none when every run finished)."""
    if not unfinished:
        return []
    lines = [
        f"**Interim report: {len(unfinished)} run(s) unfinished** (running, cut off or not started), "
        "reported as far as they got: a method may average fewer seeds at its later budgets than at "
        'its first, and its "final" success is that of its last committed phase.',
        "",
    ]
    return lines + [f"- {line}" for line in unfinished] + [""]


def summary_markdown(rows: Sequence[Row], figures: dict[str, Path], notes: dict[str, Any], levels) -> str:
    """The report: figures embedded, paired differences and demo ratios per pair of methods."""
    lines = ["# Method comparison", "", _caption(rows) + ".", "", *interim_lines(notes.get("unfinished", ()))]
    for title, path in figures.items():
        lines += [f"## {title}", "", f"![{title}]({path.name})", ""]
    lines += [f"Pearson r, metric vs final success: {notes['correlations']}.", ""]
    lines += [f"Hardest tasks: {notes['hardest']}.", ""]
    lines += ["## Paired differences of average success (method - baseline), 95% t interval over seeds", ""]
    lines += ["`*`: the interval excludes 0.", ""]
    pairs = comparison_pairs(rows)
    differences = [
        [method, baseline, f"{budget:.1f}", format_difference(interval)]
        for method, baseline in pairs
        for budget, interval in paired_rows(rows, method, baseline)
    ]
    lines.append(markdown_table(["method", "baseline", "demos per task", "difference"], differences, "llrl"))
    lines += ["", "## Demos needed to reach a level, ratio method / baseline (mean over paired seeds)", ""]
    ratios = []
    for method, baseline in pairs:
        for level in levels:
            ratio, paired, seeds = demos_ratio(rows, method, baseline, level)
            shown = "n/a" if ratio is None else f"{ratio:.2f}"
            ratios.append([method, baseline, f"{level:.0%}", shown, f"{paired}/{seeds}"])
    header = ["method", "baseline", "level", "ratio", "seeds where both reached it"]
    lines.append(markdown_table(header, ratios, "llrrr"))
    lines += ["", *reach_lines(rows, levels), *task_gap_lines(rows, notes["hardest_indices"])]
    lines += [*unseen_lines(rows), *stability_lines(rows), *cost_lines(rows)]
    return "\n".join(lines) + "\n"


def write_report(
    rows: Sequence[Row],
    task_names: Sequence[str],
    folder: Path,
    levels=LEVELS,
    unfinished: Sequence[str] = (),
) -> Path:
    """Writes every figure and ``report.md`` into ``folder``; returns the markdown path.

    Args:
        rows: The results rows (``results.results_rows``).
        task_names: The suite's task names, in task-index order.
        folder: Where the figures and ``report.md`` go.
        levels: Success levels of the reach tables and figures.
        unfinished: One line per unfinished run (``RunProgress.describe``); the report then says it
            is interim and lists them.

    Raises:
        ValueError: If there is no row.
    """
    if not rows:
        raise UserError("No evaluated round in these experiments: nothing to report.")
    folder.mkdir(parents=True, exist_ok=True)
    figures = {
        "Success against expert demos": plot_success(
            rows, "demos_per_task_mean", "expert demos per task (episodes)", folder / "success_vs_demos.png"
        ),
        "Success against expert-labelled frames": plot_success(
            rows,
            "expert_frames_per_task_mean",
            "expert-labelled frames per task",
            folder / "success_vs_frames.png",
        ),
        "Demos needed to reach a level": plot_reach(
            rows,
            levels,
            folder / "demos_to_reach.png",
            demos_of,
            "expert demos per task",
            "Demos to reach a level",
        ),
        "Wall time to reach a level": plot_reach(
            rows,
            levels,
            folder / "time_to_reach.png",
            cumulative_seconds,
            "wall time (s: collect + write + load + train + eval)",
            "Time to reach a level",
        ),
    }
    metrics_path, correlations = plot_metrics(rows, folder / "metrics_vs_success.png")
    hardest_path, hardest = plot_hardest(rows, task_names, folder / "hardest_tasks.png")
    figures["Scheduler metrics against final success"] = metrics_path
    figures["The two hardest tasks"] = hardest_path
    figures["Task need with and without the Kalman filter"] = plot_success(
        rows,
        "demos_per_task_mean",
        "expert demos per task (episodes)",
        folder / "kalman_ablation.png",
        methods={"need", "need_raw"},
    )
    if any(row.get("unseen_success_mean") is not None for row in rows):
        figures["Success on the unseen tasks"] = plot_success(
            rows,
            "demos_per_task_mean",
            "expert demos per task (episodes, training tasks)",
            folder / "unseen_success_vs_demos.png",
            y_key="unseen_success_mean",
            title="Success on unseen tasks (no task index: shared embedding)",
        )
    notes = {
        "correlations": {k: round(v, 3) for k, v in correlations.items()},
        "hardest": [task_names[t] for t in hardest],
        "hardest_indices": list(hardest),
        "unfinished": list(unfinished),
    }
    path = folder / "report.md"
    path.write_text(summary_markdown(rows, figures, notes, levels))
    return path
