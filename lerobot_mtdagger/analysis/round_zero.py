"""Round 0 shared between the DAgger methods of one seed: ``compare`` copies it instead of redoing it.

Round 0 and phase 0 come before the scheduler acts, and every random draw derives from the seed and
the round; so DAgger runs differing only in the scheduler, ``--dagger.rounds`` or result-neutral
options make them the same, to the bit. A run started beside one that has committed them copies
them and resumes at round 1 (``--share_round0=false``: each makes its own). The copy's config,
round-0 record (naming its source) and ledger are its own; the data, policy and training record are
the source's files, hard-linked where possible.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import shutil
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

from lerobot_mtdagger.datasets.config_layout import RESULT_NEUTRAL_OPTIONS, result_options
from lerobot_mtdagger.datasets.experiment_dir import (
    EXPERT_CHECK_FILE,
    ExperimentDir,
    fill_added_options,
    round_name,
    write_record_files,
)
from lerobot_mtdagger.datasets.experiment_files import CONFIG_FILE, STAGING_DIR
from lerobot_mtdagger.datasets.migrations import migrate_run_config
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

ROUND_ZERO_NEUTRAL_OPTIONS: tuple[str, ...] = (*RESULT_NEUTRAL_OPTIONS, "dagger.rounds")
"""Options (dotted paths) that cannot change a DAgger run's round 0 or phase 0, besides ``scheduler.*``."""

SCHEDULER_PREFIX = "scheduler."


def round_zero_differences(source: Mapping[str, Any], target: Mapping[str, Any]) -> list[str]:
    """The options by which two run configs (``RunConfig.to_dict``) would make different round-0s.

    Empty for DAgger runs differing only in the scheduler, ``dagger.rounds`` and result-neutral options;
    ``["mode"]`` when either is a BC run (BC's round 0 holds the whole budget).
    """
    if source.get("mode") != "dagger" or target.get("mode") != "dagger":
        return ["mode"]
    theirs, ours = (
        {
            key: value
            for key, value in result_options(migrate_run_config(config), ROUND_ZERO_NEUTRAL_OPTIONS).items()
            if not key.startswith(SCHEDULER_PREFIX)
        }
        for config in (source, target)
    )
    fill_added_options(theirs, ours, RunConfig.option_defaults())
    return sorted(key for key in theirs.keys() | ours.keys() if theirs.get(key) != ours.get(key))


def round_zero_source(runs_dir: Path, config: RunConfig, exclude: Path) -> Path | None:
    """The first run under ``runs_dir`` but ``exclude`` that committed ``config``'s round 0 and phase 0."""
    target = config.to_dict()
    for folder in sorted(path for path in Path(runs_dir).iterdir() if path.is_dir() and path != exclude):
        experiment = ExperimentDir(folder)
        if not (folder / CONFIG_FILE).is_file() or 0 not in experiment.committed_phases():
            continue
        try:
            if not round_zero_differences(experiment.read_config(), target):
                experiment.read_round_record(0)  # committed and readable
                return folder
        except UserError as error:  # a foreign or damaged folder: not a source
            logger.debug("%s is not a round-0 source: %s", folder, error)
    return None


def link_or_copy(source: str, destination: str) -> None:
    """Hard-links ``source`` at ``destination``, or copies it where the file system cannot link."""
    try:
        os.link(source, destination)
    except OSError:
        shutil.copy2(source, destination)


def copy_round_zero(source: Path, target: Path, config: RunConfig) -> None:
    """Makes ``target`` a new experiment of ``config`` holding ``source``'s round 0 and phase 0.

    Each is committed as a run commits it (a copy cut off half-way leaves a run that resumes).

    Raises:
        UserError: If ``target`` exists and is not empty, or another process is writing it.
    """
    origin, experiment = ExperimentDir(source), ExperimentDir(target)
    check = source / EXPERT_CHECK_FILE
    extra = {EXPERT_CHECK_FILE: json.loads(check.read_text())} if check.is_file() else None
    experiment.initialise(config.to_dict(), extra)
    with experiment.writer_lock():
        staged_round = experiment.rounds / STAGING_DIR / round_name(0)
        shutil.copytree(origin.round_root(0), staged_round, copy_function=link_or_copy)
        write_record_files(staged_round, own_round_zero_record(origin, config, source.name))
        os.replace(staged_round, experiment.round_root(0))
        staged_policy = experiment.policies / STAGING_DIR / round_name(0)
        shutil.copytree(origin.policy_root(0), staged_policy, copy_function=link_or_copy)
        os.replace(staged_policy, experiment.policy_root(0))
        experiment.update_ledger()


def own_round_zero_record(origin: ExperimentDir, config: RunConfig, source_name: str) -> dict[str, Any]:
    """``origin``'s round-0 record as the run of ``config`` would have written it, naming its source."""
    record = origin.read_round_record(0)
    note = (
        f"round 0 and phase 0 copied from the run {source_name} (the same seed and options but the "
        "scheduler, which acts from round 1; its timings are that run's)"
    )
    own = dataclasses.replace(
        record,
        method=config.method,
        config=config.to_dict(),
        temperature=config.scheduler.temperature,
        n_min=config.scheduler.min_episodes,
        notes=[*record.notes, note],
    )
    return own.to_dict()


def share_round_zero(folder: Path, run_args: Sequence[str]) -> Path | None:
    """Gives a run not started yet the round 0 and phase 0 of a run beside it that made the same ones.

    ``folder`` is the run's folder, ``run_args`` its ``run`` options (``--output_dir`` included).
    Returns the source run, or None (already started, a BC run, or no source yet).

    Raises:
        UserError: On bad run options, or if another process started writing ``folder`` meanwhile.
    """
    if ExperimentDir(folder).exists():
        return None
    from lerobot_mtdagger.utils.parsing import parse_options

    config = parse_options(RunConfig, run_args, "lerobot-mtdagger run")
    source = None if config.is_bc else round_zero_source(folder.parent, config, exclude=folder)
    if source is None:
        return None
    copy_round_zero(source, folder, config)
    logger.info("%s: round 0 and phase 0 copied from %s (the same by construction)", folder.name, source.name)
    return source
