"""Audits an experiment folder: every committed round and policy against its files and its record.

A round's files against their sha256, its episodes, frames and tasks against its record, and a
DAgger round's allocation recomputed and chained with the previous round and phase; a policy's
files, and that it loads. ``check_before_reading`` is what every reader runs first.
"""

from __future__ import annotations

import json
import logging
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

from lerobot_mtdagger.datasets.checkpoints import load_policy
from lerobot_mtdagger.datasets.experiment_dir import (
    EXPERT_CHECK_FILE,
    ExperimentDir,
    read_committed_json,
    round_name,
)
from lerobot_mtdagger.datasets.experiment_files import CONFIG_FILE, POLICIES_DIR, ROUNDS_DIR, TRAINING_FILE
from lerobot_mtdagger.datasets.integrity import digest_mismatches
from lerobot_mtdagger.datasets.records import RoundRecord
from lerobot_mtdagger.scheduler import allocation_mismatches
from lerobot_mtdagger.utils.errors import CorruptExperimentError, UserError

logger = logging.getLogger(__name__)


def stored_tasks(root: Path, num_tasks: int) -> tuple[list[str], list[int], int]:
    """A round's task vocabulary, episodes per task and frames, counted in its files."""
    tasks_table = read_parquet(root / "meta" / "tasks.parquet").to_pandas()
    order = [str(task) for task in tasks_table.sort_values("task_index").index]
    paths = sorted((root / "data").glob("*/*.parquet"))
    if not paths:
        raise CorruptExperimentError(f"{root / 'data'} holds no parquet file.")
    table = pa.concat_tables([read_parquet(path, ["episode_index", "task_index"]) for path in paths])
    episodes = table.column("episode_index").to_numpy()
    tasks = table.column("task_index").to_numpy()
    _, first = np.unique(episodes, return_index=True)
    counts = np.bincount(tasks[first], minlength=num_tasks)
    return order, counts.tolist(), table.num_rows


def read_parquet(path: Path, columns: list[str] | None = None) -> pa.Table:
    """Reads a parquet file of a round (``CorruptExperimentError`` naming it)."""
    try:
        return pq.read_table(path, columns=columns)
    except (OSError, pa.ArrowException) as error:
        raise CorruptExperimentError(f"{path} cannot be read ({error}).") from None


def expert_mismatches(
    run_config: dict, record: RoundRecord, added_defaults: Mapping[str, Any] | None = None
) -> list[str]:
    """How a round's experts differ from the run's ``--expert.*`` (missing options: ``added_defaults``)."""
    stored, recorded = run_config.get("expert") or {}, record.config.get("expert") or {}
    defaults = {
        path.split(".", 1)[1]: v for path, v in (added_defaults or {}).items() if path.startswith("expert.")
    }
    differing = []
    for name in sorted(set(stored) | set(recorded)):
        ours = stored.get(name, defaults.get(name, _UNKNOWN))
        theirs = recorded.get(name, defaults.get(name, _UNKNOWN))
        if _UNKNOWN not in (ours, theirs) and ours != theirs:
            differing.append(f"expert.{name}: {theirs!r} (the run's config.json: {ours!r})")
    return [f"collected with other experts: {', '.join(differing)}"] if differing else []


_UNKNOWN = object()


def verify_round(
    experiment: ExperimentDir,
    record: RoundRecord,
    previous: RoundRecord | None,
    committed_phases: set[int],
    added_defaults: Mapping[str, Any] | None = None,
) -> list[str]:
    """Checks one committed round against its data and record; one message per problem.

    ``previous`` is the previous round's record (None for round 0); ``added_defaults`` the defaults by
    dotted path of options the run's config lacks.
    """
    name = round_name(record.round)
    problems = experiment.round_file_problems(record)
    problems += expert_mismatches(experiment.read_config(), record, added_defaults)
    if record.files is None:
        problems.append("no checksums recorded (committed by an older version): files not checked")
    try:
        order, stored, frames = stored_tasks(experiment.round_root(record.round), len(record.task_names))
    except CorruptExperimentError as error:
        problems.append(str(error))
    else:
        if order != record.task_names:
            problems.append(f"task vocabulary {order} != record {record.task_names}")
        if stored != record.episodes_per_task:
            problems.append(f"data holds {stored} episodes per task, record says {record.episodes_per_task}")
        if frames != record.frames:
            problems.append(f"data holds {frames} frames, record says {record.frames}")
    before = previous.demos_so_far if previous is not None else [0] * len(record.task_names)
    if record.demos_so_far != [a + b for a, b in zip(before, record.episodes_per_task, strict=True)]:
        problems.append("demos_so_far is not the running sum of episodes_per_task")
    if record.allocation is None:
        if record.round > 0:
            problems.append("a DAgger round without an allocation record")
    else:
        problems += allocation_mismatches(record.allocation)
        if record.allocation["episodes_per_task"] != record.episodes_per_task:
            problems.append(
                f"collected {record.episodes_per_task} != allocated {record.allocation['episodes_per_task']}"
            )
        problems += _chain_mismatches(experiment, record, previous, committed_phases)
    return [f"{name}: {problem}" for problem in problems]


def _chain_mismatches(
    experiment: ExperimentDir, record: RoundRecord, previous: RoundRecord | None, committed_phases: set[int]
) -> list[str]:
    """Checks that a round's scheduler inputs are the previous round's and phase's outputs."""
    problems = []
    k = record.round
    if k - 1 in committed_phases:
        gain = experiment.read_phase_record(k - 1).gain
        if record.gain != gain:
            problems.append(f"gain {record.gain} != phase {k - 1} gain {gain}")
    if k >= 2 and previous is not None:
        if record.success_rate != previous.learner_success:
            problems.append(
                f"success_rate {record.success_rate} != previous learner-only rollouts "
                f"{previous.learner_success}"
            )
        if previous.allocation is None or record.kalman_prior != previous.allocation["kalman_posterior"]:
            problems.append(f"Kalman prior is not round {k - 1}'s posterior")
    return problems


def verify_policy(experiment: ExperimentDir, round_index: int, load: bool = True) -> list[str]:
    """Checks a committed policy folder's files and, with ``load``, that it loads (running no named code)."""
    prefix = f"policies/{round_name(round_index)}"
    try:
        record = experiment.read_phase_record(round_index)
    except UserError as error:
        return [f"{prefix}: {error}"]
    problems = experiment.phase_file_problems(record)
    if record.files is None:
        problems.append("no checksums recorded (committed by an older version): files not checked")
    if load:
        problems += _load_problems(experiment.policy_root(round_index))
    return [f"{prefix}: {problem}" for problem in problems]


def _load_problems(folder: Path) -> list[str]:
    """Whether a policy folder loads, without running code it names."""
    try:
        load_policy(folder)
    except (UserError, OSError, RuntimeError, json.JSONDecodeError) as error:
        return [f"does not load: {type(error).__name__}: {error}"]
    return []


def verify_experiment(
    experiment: ExperimentDir, added_defaults: Mapping[str, Any] | None = None, reading: bool = False
) -> tuple[int, int, list[str]]:
    """Verifies every committed round and policy; returns the rounds and policies verified and the problems.

    ``added_defaults`` (``RunConfig.option_defaults``) fills options the run's config lacks.
    ``reading=True`` skips loading the policies and takes the ledger as a resume does.

    Raises:
        NotAnExperimentError: If the folder is missing or holds no experiment.
    """
    experiment.read_config()
    try:
        rounds = experiment.committed_rounds()
    except UserError as error:
        return 0, 0, [str(error)]
    phases = experiment.committed_phases()
    problems = [problem for k in phases for problem in verify_policy(experiment, k, load=not reading)]
    readable_phases = {k for k in phases if _readable_phase(experiment, k)}
    previous = None
    for round_index in rounds:
        record = experiment.read_round_record(round_index)
        problems += verify_round(experiment, record, previous, readable_phases, added_defaults)
        previous = record
    if previous is not None:
        problems += kept_task_mismatches(experiment, previous)
    problems += experiment.ledger_problems(resuming=reading)
    return len(rounds), len(phases), problems


def kept_task_mismatches(experiment: ExperimentDir, record: RoundRecord) -> list[str]:
    """Whether the rounds hold the tasks ``expert_check.json`` kept (``--expert.min_success``)."""
    path = experiment.root / EXPERT_CHECK_FILE
    if not path.is_file():
        return []
    try:
        kept = json.loads(path.read_text())["kept"]
    except (OSError, json.JSONDecodeError, KeyError, TypeError) as error:
        return [f"{EXPERT_CHECK_FILE} cannot be read ({type(error).__name__}: {error})"]
    if kept != record.task_names:
        return [f"{EXPERT_CHECK_FILE} kept {kept}, but the rounds hold the tasks {record.task_names}"]
    return []


def _readable_phase(experiment: ExperimentDir, round_index: int) -> bool:
    """Whether a committed phase's record reads (an unreadable one is reported by ``verify_policy``)."""
    try:
        experiment.read_phase_record(round_index)
    except UserError:
        return False
    return True


UNVERIFIED_OPTION = "--unverified=true"
"""The option of every reader that reads an experiment failing verification on purpose."""

SHOWN_PROBLEMS = 3
"""Problems named in a reader's one-line refusal (``verify`` lists them all)."""


def check_before_reading(
    experiment: ExperimentDir, unverified: bool = False, added_defaults: Mapping[str, Any] | None = None
) -> list[str]:
    """What every reader (``merge``, ``report``, ``push``, ``eval``, ``shift``, ``plan``) checks first.

    The experiment is verified as ``verify`` does, without loading its policies; with ``unverified``
    (``--unverified=true``) a failure is logged and its problems returned for the output to name.

    Raises:
        NotAnExperimentError: If the folder holds no experiment.
        CorruptExperimentError: In one line naming the first problems, ``verify`` and the fix.
    """
    _, _, problems = verify_experiment(experiment, added_defaults, reading=True)
    note = experiment.ledger_note()
    if note is not None:
        logger.info(note)
    fix = (
        f"restore what is named (`lerobot-mtdagger verify --experiment_dir={experiment.root}` lists every "
        "problem)"
    )
    return _refused_or_read(f"{experiment.root} fails verification", problems, fix, unverified)


def _refused_or_read(what: str, problems: list[str], fix: str, unverified: bool) -> list[str]:
    """Refuses ``problems`` in one line, or with ``unverified`` logs a warning and returns them."""
    if not problems:
        return []
    shown = "; ".join(problems[:SHOWN_PROBLEMS])
    more = len(problems) - SHOWN_PROBLEMS
    shown += f"; and {more} more" if more > 0 else ""
    if not unverified:
        raise CorruptExperimentError(
            f"{what} ({shown}): {fix}, or pass {UNVERIFIED_OPTION} to read it as it is."
        )
    logger.warning("Reading unverified records (%s): %s (%s)", UNVERIFIED_OPTION, what, shown)
    return problems


def experiment_of(folder: Path) -> ExperimentDir | None:
    """The experiment of a ``<experiment>/rounds|policies/round-XXX`` folder, else None."""
    folder = Path(folder)
    inside = folder.parent.name in (ROUNDS_DIR, POLICIES_DIR) and folder.name.startswith("round-")
    root = folder.parent.parent
    return ExperimentDir(root) if inside and (root / CONFIG_FILE).is_file() else None


def check_policy_folder(
    folder: Path, unverified: bool = False, added_defaults: Mapping[str, Any] | None = None
) -> list[str]:
    """What ``eval``, ``shift`` and ``plan`` check of a policy folder before loading it, wherever it lives.

    A folder of an experiment: the experiment. Another: its files against its ``training.json``'s
    checksums (files a Hub download adds are left out), or an info line without them. With
    ``unverified`` the problems are returned, else raised (``CorruptExperimentError``).
    """
    folder = Path(folder)
    experiment = experiment_of(folder)
    if experiment is not None:
        return check_before_reading(experiment, unverified, added_defaults)
    recorded = carried_checksums(folder)
    if recorded is None:
        logger.info(
            "%s carries no checksums (%s with files): its files are not checked", folder, TRAINING_FILE
        )
        return []
    problems = digest_mismatches(folder, recorded, exclude=(TRAINING_FILE,), added_ok=True)
    what = f"{folder} differs from the checksums its {TRAINING_FILE} carries"
    return _refused_or_read(what, problems, "restore the policy folder", unverified)


def carried_checksums(folder: Path) -> dict[str, str] | None:
    """The checksums a policy folder's ``training.json`` carries (None: none; raises if it is unreadable)."""
    path = Path(folder) / TRAINING_FILE
    if not path.is_file():
        return None
    values = read_committed_json(path, "restore the policy folder")
    files = values.get("files") if isinstance(values, dict) else None
    return dict(files) if isinstance(files, dict) else None
