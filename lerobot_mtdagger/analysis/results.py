"""The results table of a set of experiments: one row per experiment and committed training phase.

A row describes the policy trained on rounds 0..k of one run: method and seed, the cumulative expert
demos and labelled frames per task, its evaluation success, the scheduler's signals and the round's
wall time. Saved tables read back (``read_results``, ``merge_tables``) when the runs are gone::

    <folder>/
        results.csv         one row per run x evaluated phase, list columns as JSON
        results.json        the same rows as a JSON list (what ``read_results`` reads)
        results_meta.json   {"task_names": [...], "unfinished": [...], "configs": {method: config}}
"""

from __future__ import annotations

import csv
import json
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow.parquet as pq

from lerobot_mtdagger.analysis.curves import CurvePoint, RunPoints, average_runs, curve_name
from lerobot_mtdagger.datasets.config_layout import flatten
from lerobot_mtdagger.datasets.experiment_dir import CONFIG_FILE, SavedRunRecords, open_run
from lerobot_mtdagger.datasets.migrations import migrate_run_config, stored_option
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.utils.errors import UserError

RESULTS_FILE = "results.json"
META_FILE = "results_meta.json"
PHASE_TIMINGS = ("collect_s", "write_s", "load_s", "train_s", "eval_s")
REQUIRED_COLUMNS = (
    "method",
    "seed",
    "round",
    "demos_per_task_mean",
    "expert_frames_per_task_mean",
    "eval_success_mean",
    "eval_success",
    *PHASE_TIMINGS,
)
"""The columns every saved row must have to be reported (``read_results`` checks them)."""
LIST_COLUMNS = (
    "demos_per_task",
    "expert_frames_per_task",
    "eval_success",
    "metric",
    "kalman_p",
    "raw_success",
    "gain",
    "unseen_success",
    "unseen_tasks",
)


def round_frames_per_task(root: Path, num_tasks: int) -> list[int]:
    """Frames per task stored in one round dataset (every stored frame carries an expert label)."""
    counts = np.zeros(num_tasks, dtype=np.int64)
    for path in sorted((root / "data").rglob("*.parquet")):
        task_index = pq.read_table(path, columns=["task_index"]).column("task_index").to_numpy()
        counts += np.bincount(task_index, minlength=num_tasks)[:num_tasks]
    return counts.tolist()


def experiment_rows(root: Path, label: str | None = None) -> list[dict[str, Any]]:
    """One row per evaluated phase of the experiment at ``root`` (ValueError if it has no round).

    ``label`` is the rows' method name (default: the run's method, ``bc`` for BC).
    """
    experiment = open_run(root)
    rounds = experiment.committed_rounds()
    if not rounds:
        raise UserError(f"{root} has no committed round: is it a lerobot-mtdagger experiment?")
    records = [experiment.read_round_record(k) for k in rounds]
    num_tasks = len(records[0].task_names)
    frames: np.ndarray | None = np.zeros(num_tasks, dtype=np.int64)
    total_frames = 0
    rows = []
    for k in experiment.committed_phases():
        total_frames += records[k].frames
        if isinstance(experiment, SavedRunRecords):
            frames = None  # saved records count a round's frames in total only
        else:
            frames = frames + np.asarray(round_frames_per_task(experiment.round_root(k), num_tasks))
        phase = experiment.read_phase_record(k)
        if phase.eval is None:
            continue
        rows.append(_row(root, records, k, phase, frames, total_frames / num_tasks, label))
    return rows


def _row(
    root: Path,
    records: list,
    k: int,
    phase: Any,
    frames: np.ndarray | None,
    mean_frames: float,
    label: str | None,
) -> dict[str, Any]:
    record = records[k]
    following = records[k + 1] if k + 1 < len(records) else None
    config = record.config
    demos = [int(d) for d in phase.demos_per_task]
    return {
        "experiment": str(root),
        "method": label or record.method,
        "bc": record.method == "bc",
        "seed": int(record.seed),
        "round": int(k),
        "preset": config.get("preset"),
        "demos_per_task_mean": float(np.mean(demos)),
        "demos_per_task": demos,
        "expert_frames_per_task_mean": float(mean_frames if frames is None else frames.mean()),
        "expert_frames_per_task": None if frames is None else frames.tolist(),
        "eval_success_mean": float(phase.eval_mean),
        "eval_success": [float(s) for s in phase.eval["success"]],
        "eval_episodes_per_task": int(stored_option(config, "rollout.eval_episodes") or 0),
        # The signals the scheduler saw after this phase (they decide round k+1's allocation).
        "metric": following.metric if following is not None else None,
        "kalman_p": following.kalman_posterior.get("p") if following is not None else None,
        "raw_success": following.success_rate if following is not None else None,
        "gain": None if phase.gain is None else [float(g) for g in phase.gain],
        **_progress_and_unseen(phase),
        **{name: float(phase.timings.get(name, 0.0)) for name in PHASE_TIMINGS},
    }


def _progress_and_unseen(phase: Any) -> dict[str, Any]:
    """Progress on the training tasks, success and progress on the unseen ones (None: not measured)."""
    unseen = phase.heldout_eval
    return {
        "eval_progress_mean": phase.eval.get("mean_progress"),
        "unseen_success_mean": None if unseen is None else float(unseen["mean"]),
        "unseen_success": None if unseen is None else [float(s) for s in unseen["success"]],
        "unseen_progress_mean": None if unseen is None else unseen.get("mean_progress"),
        "unseen_tasks": None if unseen is None else list(unseen["task_names"]),
    }


def results_rows(roots: Sequence[Path], labels: Mapping[Path, str] | None = None) -> list[dict[str, Any]]:
    """The rows of every experiment, sorted; ``labels`` names a folder's method where not its own."""
    labels = labels or {}
    rows = [row for root in roots for row in experiment_rows(Path(root), labels.get(Path(root)))]
    return sorted(rows, key=_row_order)


def _row_order(row: Mapping[str, Any]) -> tuple:
    """Rows sort by method, seed, demos per task and round."""
    return (row["method"], row["seed"], row["demos_per_task_mean"], row["round"])


def write_results(
    rows: Sequence[dict[str, Any]],
    folder: Path,
    task_names: Sequence[str],
    configs: Mapping[str, dict],
    unfinished: Sequence[str] = (),
    verification: Sequence[str] = (),
) -> tuple[Path, Path]:
    """Writes ``results.csv``, ``results.json``, ``results_meta.json`` into ``folder``; returns the first two.

    Args:
        rows: The rows (``results_rows``); a ``UserError`` without one.
        folder: Where they go (made if missing).
        task_names: The suite's task names in task-index order (the per-task columns' order).
        configs: The config each method's runs share (``check_comparable``).
        unfinished: One line per unfinished run of a study in progress (``RunProgress.describe``).
        verification: One line per run left out for failing verification, or read unverified.
    """
    if not rows:
        raise UserError("No evaluated training phase in these experiments: nothing to tabulate.")
    folder.mkdir(parents=True, exist_ok=True)
    json_path, csv_path = folder / RESULTS_FILE, folder / "results.csv"
    json_path.write_text(json.dumps(list(rows), indent=1))
    meta = {"task_names": list(task_names), "unfinished": list(unfinished), "configs": dict(configs)}
    if verification:
        meta["verification"] = list(verification)
    (folder / META_FILE).write_text(json.dumps(meta, indent=1))
    with csv_path.open("w", newline="") as handle:
        # Tables joined from several reports may mix rows written before a column existed.
        writer = csv.DictWriter(handle, fieldnames=list(dict.fromkeys(k for row in rows for k in row)))
        writer.writeheader()
        for row in rows:
            writer.writerow({k: json.dumps(v) if k in LIST_COLUMNS else v for k, v in row.items()})
    return csv_path, json_path


@dataclass
class SavedTable:
    """A results table read back from disk (``read_results``) or joined from several (``merge_tables``).

    Attributes:
        task_names: The task of each per-task column, in task-index order.
        unfinished: One line per run that was unfinished when the table was written.
        configs: The config each method's runs share (None: not saved with the table).
        source: Where it was read from (for messages).
        verification: One line per run left out for failing verification or read unverified.
    """

    rows: list[dict[str, Any]]
    task_names: list[str]
    unfinished: list[str]
    configs: dict[str, dict] | None
    source: str
    verification: list[str] = field(default_factory=list)


def read_results(path: Path) -> SavedTable:
    """Reads a saved ``results.json`` or its folder (``UserError`` naming a missing or foreign file)."""
    path = Path(path)
    json_path = path / RESULTS_FILE if path.is_dir() else path
    meta_path = json_path.parent / META_FILE
    for needed in (json_path, meta_path):
        if not needed.is_file():
            raise UserError(
                f"{needed} does not exist: pass the results.json that `report --output_dir` or `compare` "
                f"wrote (it keeps {META_FILE} beside it), or the folder that holds both."
            )
    rows = _read_json(json_path)
    if not isinstance(rows, list) or not rows or not all(isinstance(row, dict) for row in rows):
        raise UserError(
            f"{json_path} holds no results rows (a JSON list of objects); rewrite it with report."
        )
    missing = sorted({column for row in rows for column in REQUIRED_COLUMNS if column not in row})
    if missing:
        raise UserError(f"{json_path}: rows lack the column(s) {missing}; rewrite it with report.")
    meta = _read_json(meta_path)
    meta = meta if isinstance(meta, dict) else {}
    task_names = meta.get("task_names")
    width = {len(row["eval_success"]) for row in rows}
    if not isinstance(task_names, list) or width != {len(task_names)}:
        raise UserError(
            f"{meta_path} must name the {sorted(width)} task(s) of the rows' per-task columns in "
            '"task_names": rewrite it with report.'
        )
    return SavedTable(
        rows=rows,
        task_names=[str(name) for name in task_names],
        unfinished=[str(line) for line in meta.get("unfinished", [])],
        configs=meta.get("configs"),
        source=str(json_path),
        verification=[str(line) for line in meta.get("verification", [])],
    )


def merge_tables(tables: Sequence[SavedTable]) -> SavedTable:
    """Joins tables made apart (other seeds, other machines), refusing what would mislead (``UserError``).

    Refused: different tasks, a method's config lacking or differing, and a point (method, seed, demos
    per task, round) in two tables, which the mean would count twice.
    """
    if len(tables) == 1:
        return tables[0]
    first = tables[0]
    for table in tables:
        if table.task_names != first.task_names:
            raise UserError(
                f"{table.source} and {first.source} name different tasks ({table.task_names} vs "
                f"{first.task_names}): report them separately."
            )
        if table.configs is None:
            raise UserError(
                f"{table.source} was written without the methods' configs, so it cannot be checked against "
                "the other tables: report it alone, or rewrite it with report from its runs."
            )
    configs: dict[str, dict] = {}
    sources: dict[str, str] = {}
    for table in tables:
        assert table.configs is not None  # refused above
        for method, config in table.configs.items():
            differing = config_differences(configs.get(method, config), config)
            if differing:
                raise UserError(
                    f"Refusing to join {method} runs with different configs ({differing}) from "
                    f"{sources[method]} and {table.source}: report them separately."
                )
            configs.setdefault(method, config)
            sources.setdefault(method, table.source)
    return SavedTable(
        rows=_join_rows(tables),
        task_names=first.task_names,
        unfinished=[line for table in tables for line in table.unfinished],
        configs=configs,
        source=" + ".join(table.source for table in tables),
        verification=[line for table in tables for line in table.verification],
    )


def _join_rows(tables: Sequence[SavedTable]) -> list[dict[str, Any]]:
    """The rows of every table, sorted (``UserError`` if two tables hold the same point)."""
    seen: dict[tuple, str] = {}
    for table in tables:
        for row in table.rows:
            key = _row_order(row)
            if key in seen:
                raise UserError(
                    f"{seen[key]} and {table.source} both hold {key[0]} seed {key[1]} at {key[2]:g} demos "
                    "per task: a point in two tables would be counted twice; give each table other seeds."
                )
            seen[key] = table.source
    return sorted((row for table in tables for row in table.rows), key=_row_order)


def _read_json(path: Path) -> Any:
    """The JSON in ``path`` (``UserError`` naming the file if it is not JSON)."""
    try:
        return json.loads(path.read_text())
    except json.JSONDecodeError as error:
        raise UserError(f"{path} is not JSON ({error}); rewrite it with report.") from None


# -------------------------------------------------------------------------------------------------
# Learning curves and progress of experiment folders
# -------------------------------------------------------------------------------------------------


PER_RUN_FIELDS = (
    "seed",
    "training.seed",
    "output_dir",
    "resume",
    "progress",
    "rollout.workers",
    "rollout.worker_backend",
    "rollout.ray_address",
)
"""Options that may differ between the runs of one method (result-neutral, or what runs repeat over)."""

BC_BUDGET_FIELDS = ("dagger.rounds", "scheduler")
"""Options that may also differ between BC runs: the budget and the unused ``scheduler.*``."""


@dataclass(frozen=True)
class RunProgress:
    """How far one run in ``root`` has got: its committed ``rounds`` and ``phases`` against ``last_phase``.

    ``last_phase`` is 0 for BC, ``rounds`` for DAgger (from its config).
    """

    root: Path
    rounds: int
    phases: tuple[int, ...]
    last_phase: int

    @property
    def finished(self) -> bool:
        """Whether the last phase is committed."""
        return self.last_phase in self.phases

    def describe(self) -> str:
        """One line for a report: the run's folder name and how far it has got."""
        done = f"phases 0-{max(self.phases)}" if self.phases else "no phase yet"
        return f"{self.root.name}: {done} of 0-{self.last_phase}"


def run_progress(root: Path) -> RunProgress:
    """How far the run in ``root`` has got (``UserError`` without a config or on a corrupt round)."""
    path = Path(root) / CONFIG_FILE
    if not path.is_file():
        raise UserError(f"{root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}).")
    experiment = open_run(root)
    config = experiment.read_config()
    last_phase = 0 if config.get("mode") == "bc" else int(stored_option(config, "dagger.rounds") or 0)
    return RunProgress(
        root=Path(root),
        rounds=len(experiment.committed_rounds()),
        phases=tuple(experiment.committed_phases()),
        last_phase=last_phase,
    )


def experiment_curve(root: Path, label: str | None = None) -> RunPoints:
    """The evaluated points of one experiment folder, under ``label`` (default: its method)."""
    experiment = open_run(root)
    record = experiment.read_round_record(0)
    points = []
    for round_index in experiment.committed_phases():
        phase = experiment.read_phase_record(round_index)
        if phase.eval_mean is not None:
            points.append((round_index, float(np.mean(phase.demos_per_task)), phase.eval_mean))
    name = curve_name(label or record.method, record.method == "bc", float(np.mean(record.demos_so_far)))
    return name, record.seed, points


def learning_curves(roots: Sequence[Path], labels: Mapping[Path, str] | None = None) -> list[CurvePoint]:
    """Groups experiments by method (or ``labels``) and averages their curves over seeds, round by round.

    Raises:
        ValueError: On a repeated seed of one method, configs that differ beyond the seed, or no
            evaluated phase.
    """
    labels = labels or {}
    check_comparable(roots, labels)
    return average_runs([experiment_curve(Path(root), labels.get(Path(root))) for root in roots])


def check_comparable(roots: Sequence[Path], labels: Mapping[Path, str] | None = None) -> dict[str, dict]:
    """The options each method's runs share, refusing runs that differ beyond ``PER_RUN_FIELDS``.

    BC runs may also differ in ``BC_BUDGET_FIELDS``; a ``labels`` entry groups a run under its label.
    The ValueError names the method, the differing fields with their values and two such runs.
    """
    first_of_method: dict[str, tuple[Path, dict]] = {}
    for root in roots:
        root = Path(root)
        path = root / CONFIG_FILE
        if not path.is_file():
            raise UserError(f"{root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}).")
        config = open_run(root).read_config()
        is_bc = config.get("mode") == "bc"
        method = (labels or {}).get(root) or ("bc" if is_bc else stored_option(config, "scheduler.type"))
        ignored = PER_RUN_FIELDS + (BC_BUDGET_FIELDS if is_bc else ())
        shared = {
            key: value
            for key, value in flatten(config).items()
            if not any(key == name or key.startswith(f"{name}.") for name in ignored)
        }
        if method not in first_of_method:
            first_of_method[method] = (root, shared)
            continue
        other_root, other = first_of_method[method]
        differing = config_differences(other, shared)
        if differing:
            raise UserError(
                f"Refusing to average {method} runs with different configs ({differing}) in {other_root} "
                f"and {root}: report them separately, give one set a label of its own (report "
                "--variants), or rerun them with the same options."
            )
    return {method: shared for method, (_, shared) in first_of_method.items()}


def config_differences(first: Mapping, second: Mapping) -> str:
    """``"option: a vs b, ..."`` for every option whose value differs (empty when none does).

    Either config may be nested, flat or in an older layout; an option one lacks counts as its former
    value (``RunConfig.option_defaults``).
    """
    defaults = RunConfig.option_defaults()
    first, second = (flatten(migrate_run_config(config)) for config in (first, second))
    keys = set(first) | set(second)
    values = [{key: config.get(key, defaults.get(key)) for key in keys} for config in (first, second)]
    differing = sorted(key for key in keys if values[0][key] != values[1][key])
    return ", ".join(f"{key}: {values[0][key]!r} vs {values[1][key]!r}" for key in differing)
