"""Options of ``lerobot-mtdagger replay``: the curves replayed, the schedulers and the setting."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

from lerobot_mtdagger.analysis.saved_records import saved_records_runs
from lerobot_mtdagger.utils.paths import check_input_path, check_output_file


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

    def check_paths(self) -> None:
        """Refuses a ``--records``, ``--experiments`` or ``--results`` path that is not there.

        Raises:
            UserError: Naming the option, the path and the fix.
        """
        for folder in self.records:
            saved_records_runs(Path(folder))  # as report --records: folders or archives of runs' records
        for folder in self.experiments:
            check_input_path(folder, "--experiments", "experiment folders (the --output_dir of runs)")
        for table in self.results:
            check_input_path(table, "--results", "a results.json that report or compare wrote, or its folder")
