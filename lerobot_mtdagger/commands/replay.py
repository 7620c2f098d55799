"""``lerobot-mtdagger replay``: the schedulers replayed against measured learning curves.

The bench itself is ``analysis/replay.py``.

Tells, before a study is run, whether scheduling can pay on a task set and by how much: the share
of the oracle's headroom each scheduler captures, and the seeds a study needs to see it.
"""

from __future__ import annotations

import json
import logging
import math
import time
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.paths import check_output_file

logger = logging.getLogger(__name__)


@dataclass
class ReplayConfig:
    """Options of ``lerobot-mtdagger replay``.

    Attributes:
        records: Runs' saved records (as ``report --records``) whose per-task curves are replayed.
        experiments: Experiment folders whose per-task curves are replayed.
        results: Saved results tables (``results.json`` or its folder) whose curves are replayed.
        synthetic_tasks: With no records: this many synthetic tasks of the ``demo`` command.
        easiest: Synthetic tasks' easiest difficulty (demos per e-fold of failure).
        hardest: Synthetic tasks' hardest difficulty.
        curves: Which runs make the curves: ``bc`` (BC runs and every DAgger run's round 0), ``all``
            (every evaluated phase), or one method's name.
        methods: Schedulers to replay, each ``method`` or ``method:key=value,...``; empty: every
            registered method that needs no loss curves.
        initial_demos: Expert demos per task in round 0.
        rounds: DAgger rounds after round 0.
        budget_per_round: Episodes per round over all tasks; 0: 3 per task.
        eval_episodes: Episodes behind each measured success rate.
        n_min: Minimum episodes per task per round.
        lag: Rounds between a policy and the allocation its success informs (1: the runner's timing).
        extrapolation: Beyond the measured demos: ``flat`` or ``slope``.
        replicates: Replicate runs per scheduler.
        seed: Seed of the replicates.
        levels: Success levels of the "demos per task to reach" columns.
        output: Optional JSON file for the summaries.
    """

    records: list[Path] = field(default_factory=list)
    experiments: list[Path] = field(default_factory=list)
    results: list[Path] = field(default_factory=list)
    synthetic_tasks: int = 0
    easiest: float = 1.0
    hardest: float = 30.0
    curves: str = "bc"
    methods: list[str] = field(default_factory=list)
    initial_demos: int = 3
    rounds: int = 9
    budget_per_round: int = 0
    eval_episodes: int = 20
    n_min: int = 1
    lag: int = 1
    extrapolation: str = "flat"
    replicates: int = 2000
    seed: int = 0
    levels: list[float] = field(default_factory=lambda: [0.7, 0.8])
    output: Path | None = None

    def __post_init__(self) -> None:
        sources = (
            bool(self.records) + bool(self.experiments) + bool(self.results) + bool(self.synthetic_tasks)
        )
        if sources != 1:
            raise ValueError(
                "Give one source of curves: --records, --experiments, --results or --synthetic_tasks=N, e.g. "
                "--records='[experiments/paper-regime-training-dev/records]'."
            )
        if self.synthetic_tasks < 0 or not 0 < self.easiest <= self.hardest:
            raise ValueError("--synthetic_tasks must be >= 0 and 0 < --easiest <= --hardest.")
        if any(not 0.0 < level <= 1.0 for level in self.levels):
            raise ValueError(f"--levels must be success levels in (0, 1], got {self.levels}.")
        if self.output is not None:
            check_output_file(self.output, "--output")


def replay_command(config: ReplayConfig) -> list[dict]:
    """Replays every scheduler, prints the comparison, writes ``--output``; returns the summaries."""
    from lerobot_mtdagger.analysis.replay import ArmSpec, default_arms, run_bench

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
    from lerobot_mtdagger.analysis.headroom import fit_curves, points_from_rows
    from lerobot_mtdagger.analysis.replay import ReplaySetting, extend_curves, synthetic_curves

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
    from lerobot_mtdagger.analysis.results import merge_tables, read_results, results_rows
    from lerobot_mtdagger.analysis.saved_records import saved_records_runs
    from lerobot_mtdagger.datasets.experiment_dir import open_run

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
    from lerobot_mtdagger.analysis.replay import ONLINE_ORACLE, STATIC_ORACLE, UNIFORM, seeds_for_half_width

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
