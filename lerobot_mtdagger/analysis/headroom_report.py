"""The headroom section of a report: what the best split of the same demos could gain, per budget.

The curves come from the BC runs and DAgger's round 0 when there are BC runs, else from every
evaluated phase; writes ``headroom.json`` and ``headroom.png`` beside ``report.md``.
"""

from __future__ import annotations

import json
import logging
import math
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lerobot_mtdagger.analysis.curves import is_bc
from lerobot_mtdagger.analysis.figures import Row
from lerobot_mtdagger.analysis.headroom import (
    ALL_CURVES,
    BC_CURVES,
    best_splits,
    fit_curves,
    headroom_at,
    held_out_headroom,
    points_from_rows,
)
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

HEADROOM_FILE = "headroom.json"
READ_ME = (
    "Read: the best split of the same total demos (each task's curve known) beats an even split by `gain` "
    "in mean success, and matches the even split's success with `demos to match` per task. A scheduler "
    "can gain at most this; the held-out gain (split chosen on the other seeds) is what curves measured "
    "with this noise let anyone gain. At the ends of the measured range the best split cannot give a task "
    "more (or fewer) demos, so the gain there is 0 by construction."
)


def headroom_summary(rows: Sequence[Row], task_names: Sequence[str]) -> dict[str, Any]:
    """The headroom at every measured even budget, in sample and held out (raising as ``fit_curves``)."""
    source = BC_CURVES if any(is_bc(row) for row in rows) else ALL_CURVES
    points = points_from_rows(list(rows), source)
    curves = fit_curves(points, task_names)
    splits = best_splits(curves)
    budgets = sorted({p.demos for p in points if curves.low <= p.demos <= curves.high})
    held_out = {}
    if len(curves.seeds) > 1:
        held_out = {h.demos_per_task: h for h in held_out_headroom(points, task_names, budgets)}
    entries = []
    for budget in budgets:
        headroom = headroom_at(splits, budget)
        entry = {
            "demos_per_task": budget,
            "even": headroom.even,
            "best": headroom.best,
            "gain": headroom.gain,
            "demos_to_match": headroom.demos_to_match,
            "best_split": list(headroom.split),
        }
        if budget in held_out:
            h = held_out[budget]
            entry |= {"held_out_gain": h.mean, "held_out_low": h.low, "held_out_high": h.high}
        entries.append(entry)
    return {
        "curves": f"{source} runs" + (" (BC and every DAgger run's round 0)" if source == BC_CURVES else ""),
        "smoothing": "pooled over seeds by evaluation episodes, isotonic, linear between measured budgets",
        "seeds": list(curves.seeds),
        "measured_range": [curves.low, curves.high],
        "budgets": entries,
    }


def headroom_lines(summary: dict[str, Any]) -> list[str]:
    """The markdown section of ``report.md``."""
    lines = ["## Headroom: the best split of the same demos against an even split", "", READ_ME, ""]
    lines += [
        f"Curves: {summary['curves']}, seeds {summary['seeds']}, {summary['smoothing']}; measured "
        f"{summary['measured_range'][0]}-{summary['measured_range'][1]} demos per task.",
        "",
        "| demos per task | even split | best split | gain | demos to match | held-out gain [95%] |",
        "|---:|---:|---:|---:|---:|---:|",
    ]
    for entry in summary["budgets"]:
        match = "n/a" if entry["demos_to_match"] is None else f"{entry['demos_to_match']:.1f}"
        held = "n/a (one seed)"
        if "held_out_gain" in entry:
            low, high = entry["held_out_low"], entry["held_out_high"]
            interval = "" if math.isnan(low) else f" [{low:+.3f}, {high:+.3f}]"
            held = f"{entry['held_out_gain']:+.3f}{interval}"
        lines.append(
            f"| {entry['demos_per_task']} | {entry['even']:.3f} | {entry['best']:.3f} | "
            f"{entry['gain']:+.3f} | {match} | {held} |"
        )
    return lines + [""]


def plot_headroom(summary: dict[str, Any], path: Path) -> Path:
    """Mean success of the even and the best split against demos per task (held-out gain as bars)."""
    from lerobot_mtdagger.analysis.figures import _pyplot, _save

    plt = _pyplot()
    figure, axis = plt.subplots(figsize=(6, 4))
    budgets = [entry["demos_per_task"] for entry in summary["budgets"]]
    axis.plot(budgets, [e["even"] for e in summary["budgets"]], "o-", label="even split")
    axis.plot(budgets, [e["best"] for e in summary["budgets"]], "s-", label="best split (in sample)")
    held = [e for e in summary["budgets"] if "held_out_gain" in e and not math.isnan(e["held_out_low"])]
    if held:
        axis.errorbar(
            [e["demos_per_task"] for e in held],
            [e["even"] + e["held_out_gain"] for e in held],
            yerr=[
                [e["held_out_gain"] - e["held_out_low"] for e in held],
                [e["held_out_high"] - e["held_out_gain"] for e in held],
            ],
            fmt="^",
            capsize=3,
            label="even + held-out gain (95%)",
        )
    axis.set_xlabel("expert demos per task (even split; the best split spends the same total)")
    axis.set_ylabel("mean success over tasks")
    axis.set_title("Headroom: what any scheduler could gain")
    axis.legend()
    return _save(figure, path)


def write_headroom(
    rows: Sequence[Row], task_names: Sequence[str], folder: Path
) -> tuple[list[str], Path | None]:
    """Writes ``headroom.json`` and ``headroom.png``; returns the report lines (or one saying why not)."""
    try:
        summary = headroom_summary(rows, task_names)
    except UserError as error:
        logger.info("No headroom: %s", error)
        return ["## Headroom", "", f"Not computed: {error}", ""], None
    (folder / HEADROOM_FILE).write_text(json.dumps(summary, indent=1))
    return headroom_lines(summary), plot_headroom(summary, folder / "headroom.png")
