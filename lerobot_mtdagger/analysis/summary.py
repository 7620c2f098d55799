"""The markdown summary of a comparison (``report.md``), from a results table (``results.py``).

Paired differences, demo ratios, reach, hardest-task gaps, unseen tasks, stability and cost, each a
list of lines built from the rows; ``write_report`` writes them with the figures (``figures.py``).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

import numpy as np

from lerobot_mtdagger.analysis.curves import is_bc
from lerobot_mtdagger.analysis.figures import (
    LEVELS,
    Row,
    baselines,
    bc_methods,
    caption,
    cumulative_seconds,
    demos_of,
    frames_of,
    plot_hardest,
    plot_metrics,
    plot_reach,
    plot_success,
    point_columns,
    runs_by_method,
    seed_reach,
)
from lerobot_mtdagger.analysis.headroom_report import write_headroom
from lerobot_mtdagger.analysis.results import PHASE_TIMINGS
from lerobot_mtdagger.analysis.stats import Interval, format_difference, mean_interval, paired_difference
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.markdown import markdown_table


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

    Every method against every baseline (Uniform DAgger and each BC variant), each labelled BC variant
    against ``bc``, and task need with the Kalman filter against task need without it.
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

    Unseen: the suite's held-out tasks (never given to the scheduler); progress is the 0-3 score (touch
    the handle, pull, open). Mean over seeds with a 95% t interval.
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


def verification_lines(verification: Sequence[str]) -> list[str]:
    """The runs a report left out for failing verification or read from unverified records (none: [])."""
    if not verification:
        return []
    lines = [
        f"**Records not verified: {len(verification)} run(s)** left out for failing verification, or read "
        "from unverified records (`--unverified=true`):",
        "",
    ]
    return lines + [f"- {line}" for line in verification] + [""]


def summary_markdown(rows: Sequence[Row], figures: dict[str, Path], notes: dict[str, Any], levels) -> str:
    """The report: figures embedded, paired differences and demo ratios per pair of methods."""
    lines = ["# Method comparison", "", caption(rows) + ".", "", *interim_lines(notes.get("unfinished", ()))]
    lines += verification_lines(notes.get("verification", ()))
    for title, path in figures.items():
        lines += [f"## {title}", "", f"![{title}]({path.name})", ""]
    lines += [f"Pearson r, metric vs final success: {notes['correlations']}.", ""]
    lines += [f"Hardest tasks: {notes['hardest']}.", ""]
    lines += notes.get("headroom", [])
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
    verification: Sequence[str] = (),
) -> Path:
    """Writes every figure and ``report.md`` into ``folder``; returns the markdown path.

    Args:
        rows: The results rows (``results.results_rows``); a ValueError without one.
        task_names: The suite's task names, in task-index order.
        folder: Where the figures and ``report.md`` go.
        levels: Success levels of the reach tables and figures.
        unfinished: One line per unfinished run; the report then says it is interim and lists them.
        verification: One line per run left out for failing verification or read unverified.
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
    headroom, headroom_figure = write_headroom(rows, task_names, folder)
    if headroom_figure is not None:
        figures["Headroom: the best split against an even split"] = headroom_figure
    notes = {
        "headroom": headroom,
        "correlations": {k: round(v, 3) for k, v in correlations.items()},
        "hardest": [task_names[t] for t in hardest],
        "hardest_indices": list(hardest),
        "unfinished": list(unfinished),
        "verification": list(verification),
    }
    path = folder / "report.md"
    path.write_text(summary_markdown(rows, figures, notes, levels))
    return path
