"""``lerobot-mtdagger replay``: the schedulers replayed against measured learning curves.

The bench itself is ``analysis/replay.py``; the options are ``ReplayConfig`` (``configs/replay.py``).

Tells, before a study is run, whether scheduling can pay on a task set and by how much: the share
of the oracle's headroom each scheduler captures, and the seeds a study needs to see it.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, fields
from pathlib import Path

from lerobot_mtdagger.analysis.headroom import fit_curves, points_from_rows
from lerobot_mtdagger.analysis.replay import (
    ONLINE_ORACLE,
    STATIC_ORACLE,
    UNIFORM,
    ArmSpec,
    ReplaySetting,
    default_arms,
    extend_curves,
    run_bench,
    seeds_for_half_width,
    synthetic_curves,
)
from lerobot_mtdagger.analysis.results import merge_tables, read_results, results_rows
from lerobot_mtdagger.analysis.saved_records import saved_records_runs
from lerobot_mtdagger.commands.configs.replay import ReplayConfig
from lerobot_mtdagger.datasets.experiment_dir import open_run
from lerobot_mtdagger.utils.errors import UserError

__all__ = ["ReplayConfig", "replay_command"]


def replay_command(config: ReplayConfig) -> list[dict]:
    """Replays every scheduler, prints the comparison, writes ``--output``; returns the summaries."""
    start = time.perf_counter()
    curves, source, setting = _curves_and_setting(config)
    arms = [ArmSpec.parse(text) for text in config.methods] if config.methods else default_arms()
    summaries = run_bench(curves, setting, arms, config.levels)
    lines = _table(summaries, config.levels) + _footer(
        summaries, source, setting, time.perf_counter() - start
    )
    print("\n".join(lines))
    records = [asdict(summary) for summary in summaries]
    if config.output is not None:
        payload = {"source": source, "setting": asdict(setting), "arms": records}
        config.output.parent.mkdir(parents=True, exist_ok=True)
        config.output.write_text(json.dumps(payload, indent=1, default=str))
        print(f"wrote {config.output}")
    return records


def _curves_and_setting(config: ReplayConfig):
    """The replayed curves, a line saying where they come from, and the replay's setting."""
    num_tasks = config.synthetic_tasks
    rows, task_names = ([], []) if num_tasks else _rows(config)
    num_tasks = num_tasks or len(task_names)
    # The command's options of the same names are the setting's; 0 budget means 3 per task.
    options = {f.name: getattr(config, f.name) for f in fields(ReplaySetting)}
    setting = ReplaySetting(**options | {"budget_per_round": config.budget_per_round or 3 * num_tasks})
    if config.synthetic_tasks:
        source = (
            f"{num_tasks} synthetic tasks, 1 - exp(-n / d), d from {config.easiest:g} to {config.hardest:g}"
        )
        return synthetic_curves(num_tasks, config.easiest, config.hardest, setting), source, setting
    measured = fit_curves(points_from_rows(rows, config.curves), task_names)
    seeds = ", ".join(str(seed) for seed in measured.seeds)
    source = (
        f"{num_tasks} tasks' curves from {config.curves} runs (seeds {seeds}), measured {measured.low}-"
        f"{measured.high} demos per task, {config.extrapolation} beyond"
    )
    return extend_curves(measured, setting), source, setting


def _rows(config: ReplayConfig) -> tuple[list[dict], list[str]]:
    """Results rows and task names of the runs or tables the options name."""
    if config.results:
        saved = merge_tables([read_results(path) for path in config.results])
        return saved.rows, saved.task_names
    roots = list(config.experiments) + [
        run for folder in config.records for run in saved_records_runs(folder)
    ]
    for root in roots:
        if not Path(root).exists():
            raise UserError(f"{root} does not exist: give experiment folders or saved records.")
    return results_rows(roots), open_run(roots[0]).read_round_record(0).task_names


def _table(summaries, levels) -> list[str]:
    """The comparison as a markdown table."""
    reach = " | ".join(f"demos to {level:g}" for level in levels)
    lines = [
        "| scheduler | mean success | - uniform [95%] | share of headroom [95%] | SD per replicate | "
        f"{reach} | s |",
        "|---|---:|---:|---:|---:|" + "---:|" * len(levels) + "---:|",
    ]
    for summary in summaries:
        difference = "{:+.4f} [{:+.4f}, {:+.4f}]".format(*summary.vs_uniform)
        share = "-" if math.isnan(summary.share[0]) else "{:+.2f} [{:+.2f}, {:+.2f}]".format(*summary.share)
        demos = " | ".join(
            "not reached" if summary.demos_to_reach[level] is None else f"{summary.demos_to_reach[level]:.1f}"
            for level in levels
        )
        lines.append(
            f"| {summary.label} | {summary.mean_success:.3f} | {difference} | {share} | "
            f"{summary.replicate_sd:.4f} | {demos} | {summary.seconds:.1f} |"
        )
    return lines


def _footer(summaries, source: str, setting, seconds: float) -> list[str]:
    """Where the curves come from, how to read the table, and the seeds a study would need."""
    schedulers = [s for s in summaries if s.label not in (UNIFORM, ONLINE_ORACLE, STATIC_ORACLE)]
    lines = [
        f"curves: {source}",
        f"setting: {setting.initial_demos} initial demos per task, {setting.rounds} rounds of "
        f"{setting.budget_per_round}, {setting.eval_episodes} evaluation episodes, lag {setting.lag}, "
        f"{setting.replicates} replicates; {seconds:.1f} s",
        "read: mean success over the budgets after round 0; share = (scheduler - uniform) / (online oracle - "
        "uniform); the static oracle is the best split of the same demos at each budget (the headroom).",
    ]
    if schedulers:
        best = max(schedulers, key=lambda s: s.vs_uniform[0])
        seeds = seeds_for_half_width(best.vs_uniform[0], best.replicate_sd)
        lines.append(
            f"power: {best.label} - uniform {best.vs_uniform[0]:+.4f}; a paired study needs "
            f"{seeds if seeds is not None else 'more than 100'} seeds for a 95% half-width of half that "
            f"with this replicate SD ({best.replicate_sd:.4f}); training noise adds to it in a real study."
        )
    return lines
