"""``lerobot-mtdagger report``: eval success against expert demos per method, mean and std over seeds.

From run folders (``--experiments``, ``--compare_dir``, ``--variants``), runs' saved records
(``--records``) or saved results tables (``--results``); with an output folder also the figures and
a summary with paired differences. Its options are ``ReportConfig`` (``configs/report.py``).
"""

from __future__ import annotations

import json
import logging
from collections.abc import Sequence
from pathlib import Path

from lerobot_mtdagger.analysis.curves import curves_from_rows, curves_table
from lerobot_mtdagger.analysis.headroom_report import HEADROOM_FILE, headroom_lines
from lerobot_mtdagger.analysis.results import (
    check_comparable,
    learning_curves,
    merge_tables,
    read_results,
    results_rows,
    run_progress,
    write_results,
)
from lerobot_mtdagger.analysis.saved_records import shown_name
from lerobot_mtdagger.analysis.summary import write_report
from lerobot_mtdagger.commands.configs.report import ReportConfig
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, is_saved_records, open_run
from lerobot_mtdagger.datasets.verify import check_before_reading
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.utils.errors import CorruptExperimentError, NotAnExperimentError, UserError

__all__ = ["ReportConfig", "report_command", "verified_runs"]

logger = logging.getLogger(__name__)


def report_command(config: ReportConfig) -> str:
    """Prints the learning curves (mean and std over seeds); writes the figures and summary.

    Runs still being written (or cut off) are reported as far as they got: a run without a committed
    round is left out, and the report says which runs are unfinished. With ``--results``, the same
    from a saved results table.
    """
    if config.results:
        return _report_saved_tables(config)
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
    assert config.output_dir is not None  # ReportConfig sets it for --results
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
    assert config.output_dir is not None  # the callers write figures only with an --output_dir
    path = write_report(
        rows, task_names, config.output_dir, config.levels, unfinished=unfinished, verification=verification
    )
    _print_headroom(config.output_dir)
    print(f"figures and summary: {path}")


def _print_headroom(folder: Path) -> None:
    """Prints the headroom table ``write_report`` saved (nothing when the runs could not give one)."""
    saved = folder / HEADROOM_FILE
    if saved.is_file():
        print("\n".join(headroom_lines(json.loads(saved.read_text()))))
