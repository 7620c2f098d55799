"""``lerobot-mtdagger report``: eval success against expert demos per method, mean and std over seeds.

From run folders (``--experiments``, ``--compare_dir``, ``--variants``), runs' saved records
(``--records``) or saved results tables (``--results``); with an output folder also the figures and
a summary with paired differences.
"""

from __future__ import annotations

import logging
from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.paths import check_output_dir, check_output_file

logger = logging.getLogger(__name__)


@dataclass
class ReportConfig:
    """Options of ``lerobot-mtdagger report``: success against expert demos, method by method.

    Attributes:
        experiments: Experiment directories (several seeds of several methods).
        compare_dir: A ``compare`` folder (its runs are the experiments); instead of ``experiments``.
        output_dir: Folder for the figures and ``report.md`` (default ``<compare_dir>/report``; with
            ``experiments`` only, no figures unless given).
        output: Optional markdown file for the table.
        levels: Success levels of the "demos to reach" and "time to reach" figures.
        variants: More runs reported under a method name of their own, by name: a ``compare`` folder
            or one experiment each, e.g. ``--variants='{bc-balanced: outputs/bc-balanced}'`` for BC
            trained with balanced sampling beside the ``bc`` of ``compare_dir``. A BC variant is a
            baseline like ``bc``.
        results: Saved results tables instead of run folders: each a ``results.json`` that ``report
            --output_dir`` or ``compare`` wrote, or its folder. Draws the figures and ``report.md`` from
            the tables alone, e.g. after the run folders are gone, with other ``--levels``, or joining
            seeds run on other machines (each point in one table only; the methods' configs must
            agree). Default ``output_dir`` for one table: its folder.
        records: Runs' saved records (``scripts/save_run_records.sh``: config, round and training
            records, no frames or weights), each a run's records folder, a folder of them, or a
            study's ``runs-records.tar.gz`` (or a folder holding them: ``analysis.saved_records``), reported
            beside ``experiments`` and ``compare_dir`` as their runs are: a study whose ``outputs/`` was
            lost keeps its finished runs. Their frames per task are known only on average.
        unverified: Report runs that fail verification (a changed record or file, a missing ledger) as
            they are, with a warning, and say so in ``report.md``; by default each is left out, named
            with the reason, and the report goes on with the rest.
    """

    experiments: list[Path] = field(default_factory=list)
    compare_dir: Path | None = None
    results: list[Path] = field(default_factory=list)
    output_dir: Path | None = None
    output: Path | None = None
    levels: list[float] = field(default_factory=lambda: [0.5, 0.6, 0.7, 0.8])
    variants: dict[str, Path] = field(default_factory=dict)
    records: list[Path] = field(default_factory=list)
    unverified: bool = False

    def __post_init__(self) -> None:
        if self.results:
            self._check_results_options()
            return
        if not self.experiments and self.compare_dir is None and not self.records:
            raise ValueError(
                "--experiments, --compare_dir, --records or --results is required, e.g. "
                "--experiments='[outputs/need-s0,outputs/bc-s0]', --compare_dir=outputs/compare, "
                "--records='[experiments/pixels-eval/records]' or "
                "--results='[experiments/mt10-state-eval/report]'."
            )
        for folder in self.records:
            _saved_records_runs(Path(folder))  # refuses a folder without records now, not mid-report
        if self.compare_dir is not None and not (self.compare_dir / "runs").is_dir():
            raise ValueError(f"{self.compare_dir} is not a compare folder (no runs/ in it).")
        if self.compare_dir is not None and self.output_dir is None:
            self.output_dir = self.compare_dir / "report"
        self._check_outputs()
        from lerobot_mtdagger.datasets.experiment_dir import CONFIG_FILE

        for name, folder in self.variants.items():
            if not (Path(folder) / "runs").is_dir() and not (Path(folder) / CONFIG_FILE).is_file():
                raise ValueError(
                    f"--variants: {folder} (for {name!r}) is neither a compare folder (runs/) nor an "
                    "experiment: give the folder compare or run wrote."
                )

    def _check_results_options(self) -> None:
        """``--results`` goes without run folders; several tables need an ``--output_dir``."""
        if self.experiments or self.compare_dir is not None or self.variants or self.records:
            raise ValueError(
                "--results draws saved tables: give it alone, without --experiments, --compare_dir, "
                "--variants or --records (their runs are tabulated afresh instead)."
            )
        if self.output_dir is None and len(self.results) > 1:
            raise ValueError(
                f"--results joins {len(self.results)} tables: give --output_dir for the joined report "
                "(it is never written into one of the tables' folders unasked)."
            )
        if self.output_dir is None:
            table = Path(self.results[0])
            self.output_dir = table if table.is_dir() else table.parent
        self._check_outputs()

    def _check_outputs(self) -> None:
        """Refuses an output folder or file that cannot be written, before any table is made."""
        if self.output_dir is not None:
            check_output_dir(self.output_dir, "--output_dir")
        if self.output is not None:
            check_output_file(self.output, "--output")

    @property
    def experiment_dirs(self) -> list[Path]:
        """The experiments to report on (the variants' last)."""
        mine = list(self.experiments)
        if self.compare_dir is not None:
            mine += _compare_runs(self.compare_dir)
        for folder in self.records:
            mine += _saved_records_runs(Path(folder))
        return mine + list(self.labels)

    @property
    def labels(self) -> dict[Path, str]:
        """The method name of each variant's experiments."""
        return {
            run: name
            for name, folder in self.variants.items()
            for run in (_compare_runs(Path(folder)) if (Path(folder) / "runs").is_dir() else [Path(folder)])
        }

    @property
    def runs_not_started(self) -> list[str]:
        """The runs the compare folders plan (``compare.json``) that have no folder yet."""
        from lerobot_mtdagger.analysis.compare import runs_not_started

        folders = [self.compare_dir] if self.compare_dir is not None else []
        folders += [Path(folder) for folder in self.variants.values() if (Path(folder) / "runs").is_dir()]
        return [f"{name}: not started" for folder in folders for name in runs_not_started(folder)]


def _compare_runs(compare_dir: Path) -> list[Path]:
    """The run folders of a ``compare`` folder."""
    return sorted(p for p in (compare_dir / "runs").iterdir() if p.is_dir())


def _saved_records_runs(folder: Path) -> list[Path]:
    """The runs' records at ``folder`` (``analysis.saved_records``: folders or archives)."""
    from lerobot_mtdagger.analysis.saved_records import saved_records_runs

    return saved_records_runs(folder)


def report_command(config: ReportConfig) -> str:
    """Prints the learning curves (mean and std over seeds); writes the figures and summary.

    Runs still being written (or cut off) are reported as far as they got: a run without a committed
    round is left out, and the report says which runs are unfinished. With ``--results``, the same
    from a saved results table.
    """
    if config.results:
        return _report_saved_tables(config)
    from lerobot_mtdagger.analysis.curves import curves_table
    from lerobot_mtdagger.analysis.results import check_comparable, learning_curves, run_progress

    all_roots, verification = verified_runs(config.experiment_dirs, config.unverified)
    labels = {run: name for run, name in config.labels.items() if run in all_roots}
    configs = check_comparable(all_roots, labels)
    progress = [run_progress(root) for root in all_roots]
    unfinished = [run.describe() for run in progress if not run.finished] + config.runs_not_started
    if unfinished:
        logger.warning(
            "Interim report: %d run(s) unfinished (running, cut off or not started), reported as far "
            "as they got: %s",
            len(unfinished),
            "; ".join(unfinished),
        )
    roots = [run.root for run in progress if run.rounds > 0]
    if not roots:
        raise UserError(
            f"None of the {len(progress)} run(s) has a committed round yet: report once the first "
            "round is written."
        )
    table = _print_table(curves_table(learning_curves(roots, labels)), config)
    if config.output_dir is not None:
        from lerobot_mtdagger.analysis.results import results_rows, write_results
        from lerobot_mtdagger.analysis.saved_records import shown_name
        from lerobot_mtdagger.datasets.experiment_dir import open_run

        rows = results_rows(roots, labels)
        for row in rows:
            row["experiment"] = shown_name(Path(row["experiment"]))
        task_names = open_run(roots[0]).read_round_record(0).task_names
        write_results(rows, config.output_dir, task_names, configs, unfinished, verification)
        _write_figures(rows, task_names, config, unfinished, verification)
    return table


def verified_runs(roots: list[Path], unverified: bool) -> tuple[list[Path], list[str]]:
    """The runs to report, each run folder checked as every reader checks it (``check_before_reading``).

    A run that fails is left out with a warning naming it and why (or, with ``unverified``, reported
    from its records as they are). Saved records hold no frames or weights and are read as they are.

    Returns:
        The runs to report, and one line per run left out or read unverified.

    Raises:
        UserError: If every run fails verification.
    """
    from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, is_saved_records
    from lerobot_mtdagger.datasets.verify import check_before_reading
    from lerobot_mtdagger.runner.configs import RunConfig
    from lerobot_mtdagger.utils.errors import CorruptExperimentError, NotAnExperimentError

    defaults = RunConfig.option_defaults()
    kept, lines = [], []
    for root in roots:
        if is_saved_records(root):
            kept.append(root)
            continue
        try:
            problems = check_before_reading(ExperimentDir(root), unverified, defaults)
        except NotAnExperimentError:  # not started yet: its progress says so
            problems = []
        except CorruptExperimentError as error:
            lines.append(f"{root}: left out, {error}")
            continue
        kept.append(root)
        if problems:
            lines.append(f"{root}: read from unverified records ({'; '.join(problems)})")
    if not kept:
        raise UserError(f"None of the {len(roots)} run(s) can be reported: {' | '.join(lines)}")
    for line in lines:
        logger.warning("Report: %s", line)
    return kept, lines


def _report_saved_tables(config: ReportConfig) -> str:
    """``report --results``: the table, figures and summary of saved results tables, joined.

    Several tables joined are also saved as one (``results.csv``, ``results.json``, beside the figures),
    as ``report`` saves the table of the runs it reads; one table is where it was read from.
    """
    from lerobot_mtdagger.analysis.curves import curves_from_rows, curves_table
    from lerobot_mtdagger.analysis.results import merge_tables, read_results, write_results

    saved = merge_tables([read_results(path) for path in config.results])
    if len(config.results) > 1:
        assert saved.configs is not None  # merge_tables refuses tables without them
        write_results(
            saved.rows,
            config.output_dir,
            saved.task_names,
            saved.configs,
            saved.unfinished,
            saved.verification,
        )
    table = _print_table(curves_table(curves_from_rows(saved.rows)), config)
    _write_figures(saved.rows, saved.task_names, config, saved.unfinished, saved.verification)
    return table


def _print_table(table: str, config: ReportConfig) -> str:
    """Prints the learning-curve table and writes it to ``--output`` when given; returns it."""
    print(table)
    if config.output is not None:
        config.output.write_text(table + "\n")
    return table


def _write_figures(
    rows: list[dict],
    task_names: list[str],
    config: ReportConfig,
    unfinished: list[str],
    verification: Sequence[str] = (),
) -> None:
    """Writes every figure and ``report.md`` into ``--output_dir`` and prints where."""
    from lerobot_mtdagger.analysis.summary import write_report

    path = write_report(
        rows, task_names, config.output_dir, config.levels, unfinished=unfinished, verification=verification
    )
    _print_headroom(config.output_dir)
    print(f"figures and summary: {path}")


def _print_headroom(folder: Path) -> None:
    """Prints the headroom table ``write_report`` saved (nothing when the runs could not give one)."""
    import json

    from lerobot_mtdagger.analysis.headroom_report import HEADROOM_FILE, headroom_lines

    saved = folder / HEADROOM_FILE
    if saved.is_file():
        print("\n".join(headroom_lines(json.loads(saved.read_text()))))
