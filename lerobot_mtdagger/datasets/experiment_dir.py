"""Round datasets and training phases of a Multitask DAgger experiment, on disk.

Layout of an experiment directory::

    <output_dir>/
        config.json                  the run config (written once; a resume must match it)
        run.log                      log of every run and resume
        rounds/
            round-000/               LeRobotDataset v3.0 of round 0 (expert demonstrations)
                meta/mtdagger.json   the round's record (allocation, Kalman state, ...): the truth
                meta/info.json       ... "mtdagger": a mirror of it on LeRobot 0.4 only
            round-001/               LeRobotDataset of round 1 (DAgger rollouts, expert labels)
            .staging/round-002/      a round being written: never read, deleted on resume
        policies/
            round-000/               policy trained on rounds 0..0 (LeRobot pretrained model +
                                     processors) and training.json (per-task losses, gain, eval)
            .staging/round-001/      a training phase being written
            .progress/round-001.pt   its progress, saved every few minutes; a resume goes on from it

A round or phase is committed by an atomic rename of its finished staging folder, so a committed
round is immutable and complete. Every round holds the experiment's full task vocabulary in the same
order, so task_index i is the same task in every round and in merged datasets.
"""

from __future__ import annotations

import contextlib
import dataclasses
import fcntl
import json
import logging
import os
import shutil
from collections.abc import Iterator, Mapping, Sequence
from pathlib import Path
from typing import Any

import pyarrow as pa
import pyarrow.parquet as pq
from lerobot.datasets.lerobot_dataset import LeRobotDataset
from lerobot.datasets.utils import update_chunk_file_indices

from lerobot_mtdagger.datasets.config_layout import RESULT_NEUTRAL_OPTIONS, result_options
from lerobot_mtdagger.datasets.experiment_files import (
    CONFIG_FILE,
    LOCK_FILE,
    PARTIAL_SUFFIX,
    POLICIES_DIR,
    PROGRESS_DIR,
    ROUNDS_DIR,
    STAGING_DIR,
    TRAINING_FILE,
    check_experiment_folder,
)
from lerobot_mtdagger.datasets.integrity import digest_mismatches, folder_digests
from lerobot_mtdagger.datasets.ledger import LEDGER_FILE, Ledger
from lerobot_mtdagger.datasets.migrations import migrate_run_config, pre_ledger_note, resume_hint
from lerobot_mtdagger.datasets.records import (
    FORMAT_VERSION,
    RECORD_KEY,
    PhaseRecord,
    RoundRecord,
    has_provenance,
    round_features,
)
from lerobot_mtdagger.datasets.round_writer import EpisodeFrames, write_round_episodes
from lerobot_mtdagger.utils.errors import CorruptExperimentError, NotAnExperimentError, UserError
from lerobot_mtdagger.utils.lerobot_compat import INFO_KEEPS_OTHER_KEYS
from lerobot_mtdagger.utils.quiet import quiet_third_party

logger = logging.getLogger(__name__)

EXPERT_CHECK_FILE = "expert_check.json"
"""The measurement that chose an experiment's tasks (``--expert.min_success``, ``rollout.expert_check``)."""


STATS_FILE = "meta/stats.json"
INFO_FILE = "meta/info.json"
"""LeRobot's dataset info; its ``mtdagger`` key mirrors the round's record (or holds the only copy)."""

RECORD_FILE = "meta/mtdagger.json"
"""The round's record, in a file LeRobot never rewrites: readers and ``verify`` take it as the truth."""

RECORD_FILES = (INFO_FILE, RECORD_FILE)
"""The files of a round that its checksums do not cover (they hold the record, checksums included)."""


class ExperimentLockedError(UserError):
    """Another process holds the writer lock of an experiment folder."""


DATASET_FPS = 80

VIDEO_BACKEND = "pyav"
"""The decoder named when a round is created: rounds hold no video, and naming one keeps LeRobot >= 0.5
from probing torchcodec (a warning per dataset where FFmpeg's libraries are absent).
"""


def writer_lock_holder(root: Path) -> str | None:
    """Who holds ``root``'s writer lock: its pid, or None (probed without creating anything)."""
    path = root / LOCK_FILE
    if not path.is_file():
        return None
    descriptor = os.open(path, os.O_RDONLY)
    try:
        try:
            fcntl.flock(descriptor, fcntl.LOCK_SH | fcntl.LOCK_NB)
        except BlockingIOError:
            return os.pread(descriptor, 64, 0).decode(errors="replace").strip() or "unknown"
        return None
    finally:
        os.close(descriptor)  # closing releases the probe's lock


def round_name(round_index: int) -> str:
    """Folder and Hub revision name of a round: ``round-{k:03d}``."""
    return f"round-{round_index:03d}"


def write_json_atomic(path: Path, payload: Any) -> None:
    """Writes JSON to ``path`` through a temporary file and an atomic rename."""
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(payload, indent=2, allow_nan=False))
    os.replace(tmp, path)


def write_record_files(root: Path, record: dict[str, Any]) -> None:
    """Writes a dataset's record (``meta/mtdagger.json``) and, on LeRobot 0.4, its ``meta/info.json`` mirror.

    Each file is written anew (a hard link to the former one is left intact); LeRobot 0.6, which warns
    of unknown ``info.json`` keys, gets no mirror.
    """
    info_path = root / INFO_FILE
    info = json.loads(info_path.read_text())
    write_json_atomic(root / RECORD_FILE, record)
    if INFO_KEEPS_OTHER_KEYS:
        write_json_atomic(info_path, {**info, RECORD_KEY: record})
    elif RECORD_KEY in info:
        del info[RECORD_KEY]
        write_json_atomic(info_path, info)


def read_committed_json(path: Path, fix: str) -> Any:
    """Reads a JSON file of a committed round or phase (``CorruptExperimentError`` naming it and ``fix``)."""
    try:
        return json.loads(path.read_text())
    except (OSError, json.JSONDecodeError) as error:
        raise CorruptExperimentError(f"{path} is unreadable ({error}); {fix}.") from None


def fill_added_options(stored: dict[str, Any], given: Mapping[str, Any], added: Mapping[str, Any]) -> None:
    """Gives ``stored`` each option of ``added`` it lacks where ``given`` holds that option's former value.

    ``added`` maps an option's dotted path to its value before the option existed.
    """
    for key, default in added.items():
        if key in given and key not in stored and given[key] == default:
            stored[key] = default


def adds_dagger_rounds(stored: Mapping[str, Any], given: Mapping[str, Any]) -> bool:
    """Whether ``given`` asks a stored DAgger run for more rounds (and maybe nothing else)."""
    stored_rounds, given_rounds = stored.get(ROUNDS_OPTION), given.get(ROUNDS_OPTION)
    return (
        stored.get("mode") != "bc"
        and given.get("mode") == stored.get("mode")
        and isinstance(stored_rounds, int)
        and isinstance(given_rounds, int)
        and given_rounds > stored_rounds
    )


ROUNDS_OPTION = "dagger.rounds"
ROUNDS_HINT = (
    " (--dagger.rounds may only grow, and only for a DAgger run: BC's one round holds the demos of "
    "every round)"
)


def _only(frame: Mapping[str, Any], features: Mapping[str, Any]) -> dict[str, Any]:
    """The frame's values of ``features`` (a round without provenance columns drops them)."""
    return {key: value for key, value in frame.items() if key in features}


def round_record_from_info(path: Path, info_path: Path) -> RoundRecord:
    """The round record mirrored under ``mtdagger`` in ``info_path`` (``CorruptExperimentError`` if none)."""
    info = read_committed_json(info_path, "restore it, or move the round out of the experiment directory")
    return round_record_from(info.get(RECORD_KEY) if isinstance(info, dict) else None, path, info_path)


def round_record_from(record: Any, path: Path, info_path: Path) -> RoundRecord:
    """The committed round record ``record`` from ``info_path`` (``CorruptExperimentError`` if not one)."""
    if not isinstance(record, dict) or record.get("format_version") != FORMAT_VERSION:
        raise CorruptExperimentError(
            f"{path} is not a lerobot-mtdagger round (no '{RECORD_KEY}' record of format "
            f"{FORMAT_VERSION} in {info_path}); move it out of the experiment directory."
        )
    if not record.get("committed"):
        raise CorruptExperimentError(
            f"{path} holds an uncommitted round record; move it out of the experiment directory."
        )
    return RoundRecord.from_dict(record, where=f"The round record in {info_path}")


def committed_into_ledger(path: Path) -> bool:
    """Whether a record file says it was committed into the experiment's ledger (unreadable: False)."""
    try:
        values = json.loads(Path(path).read_text())
    except (OSError, json.JSONDecodeError):
        return False  # named by the record's own checks
    if isinstance(values, dict) and path.name == Path(INFO_FILE).name:
        values = values.get(RECORD_KEY)
    return isinstance(values, dict) and values.get("ledger") is True


class ExperimentDir:
    """The on-disk state of one experiment at ``root`` (see the module docstring for the layout)."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.rounds = self.root / ROUNDS_DIR
        self.policies = self.root / POLICIES_DIR

    # ---------------------------------------------------------------------------------------------
    # Creation and checks
    # ---------------------------------------------------------------------------------------------

    def exists(self) -> bool:
        """Whether the directory exists and is not empty."""
        return self.root.exists() and any(self.root.iterdir())

    def initialise(self, config: dict[str, Any], extra: Mapping[str, Any] | None = None) -> None:
        """Creates the experiment (``extra``: JSON files by name) beside ``root``, then renames it there.

        Raises:
            UserError: If the directory exists and is not empty.
        """
        if self.exists():
            raise UserError(
                f"Output directory {self.root} already exists and is not empty: pass --resume=true to "
                "continue that experiment, or choose another --output_dir."
            )
        self.root.parent.mkdir(parents=True, exist_ok=True)
        building = self.root.parent / f".{self.root.name}.creating-{os.getpid()}"
        if building.exists():
            shutil.rmtree(building)
        try:
            (building / ROUNDS_DIR).mkdir(parents=True)
            (building / POLICIES_DIR).mkdir()
            write_json_atomic(building / CONFIG_FILE, config)
            for name, content in (extra or {}).items():
                write_json_atomic(building / name, content)
            os.replace(building, self.root)  # replaces an empty root too
        finally:
            if building.exists():  # the start failed before the rename: leave nothing
                shutil.rmtree(building)

    @contextlib.contextmanager
    def writer_lock(self, record_pid: bool = True) -> Iterator[None]:
        """Holds the writer lock (``flock`` on ``<root>/.lock``, holding the pid): one writer at a time.

        Raises:
            ExperimentLockedError: At once, if another process holds the lock, naming it.
        """
        self.root.mkdir(parents=True, exist_ok=True)
        descriptor = os.open(self.root / LOCK_FILE, os.O_RDWR | os.O_CREAT, 0o644)
        try:
            try:
                fcntl.flock(descriptor, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(descriptor, 64, 0).decode(errors="replace").strip() or "unknown"
                raise ExperimentLockedError(
                    f"{self.root} is being written by another run (pid {holder}); wait for it to finish "
                    f"or stop it, then pass --resume=true."
                ) from None
            if record_pid:
                os.ftruncate(descriptor, 0)
                os.pwrite(descriptor, str(os.getpid()).encode(), 0)
            yield
        finally:
            os.close(descriptor)  # closing releases the lock

    def check_resumable(
        self,
        config: dict[str, Any],
        ignore: Sequence[str] = RESULT_NEUTRAL_OPTIONS,
        added_defaults: Mapping[str, Any] | None = None,
    ) -> None:
        """Checks that ``root`` holds an experiment started with the same config, option by option.

        May differ: options in ``ignore``; a larger ``dagger.rounds`` of a DAgger run (``extend_rounds``);
        an option the stored config lacks, given its default in ``added_defaults`` (by dotted path).

        Raises:
            NotAnExperimentError: If there is no experiment to resume.
            UserError: If the config differs in an option that changes results.
        """
        if not self.root.exists():
            raise NotAnExperimentError(
                f"Nothing to resume: {self.root} does not exist (drop --resume to start)."
            )
        stored_config = self.read_config()
        stored = result_options(migrate_run_config(stored_config), ignore)
        given = result_options(migrate_run_config(config), ignore)
        fill_added_options(stored, given, added_defaults or {})
        if adds_dagger_rounds(stored, given):
            stored[ROUNDS_OPTION] = given[ROUNDS_OPTION]
        differing = sorted(key for key in set(stored) | set(given) if stored.get(key) != given.get(key))
        if differing:
            details = ", ".join(f"{k}: {stored.get(k)!r} -> {given.get(k)!r}" for k in differing)
            if ROUNDS_OPTION in differing:
                hint = ROUNDS_HINT
            else:
                hint = resume_hint(stored_config, differing, stored)
            raise UserError(
                f"Cannot resume {self.root} with a different config ({details}){hint}: resume with "
                "the stored values, or start a new --output_dir."
            )

    def extend_rounds(self, rounds: int) -> None:
        """Raises the stored ``dagger.rounds`` to ``rounds`` (after ``check_resumable``, lock held)."""
        config = self.read_config()
        stored = config["dagger"]["rounds"]
        if rounds > stored:
            logger.info("Extending %s from %d to %d DAgger rounds", self.root, stored, rounds)
            config["dagger"]["rounds"] = rounds
            write_json_atomic(self.root / CONFIG_FILE, config)

    def read_config(self) -> dict[str, Any]:
        """The stored run config in today's layout (``NotAnExperimentError`` if there is no readable one)."""
        config_path = self.root / CONFIG_FILE
        check_experiment_folder(self.root)
        try:
            return migrate_run_config(json.loads(config_path.read_text()))
        except FileNotFoundError:
            raise NotAnExperimentError(
                f"{self.root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}): pass the "
                "--output_dir of a `lerobot-mtdagger run`; the folder was left untouched."
            ) from None
        except (OSError, json.JSONDecodeError) as error:
            raise CorruptExperimentError(f"{config_path} is unreadable ({error}).") from None

    def check_committed_files(self) -> None:
        """Refuses an experiment whose committed files changed (``CorruptExperimentError`` naming each)."""
        problems = []
        for round_index in self.committed_rounds():
            problems += self.round_file_problems(self.read_round_record(round_index))
        for round_index in self.committed_phases():
            problems += self.phase_file_problems(self.read_phase_record(round_index))
        problems += self.ledger_problems(resuming=True)
        if problems:
            raise CorruptExperimentError(
                f"{self.root} was changed after commit: {'; '.join(problems)}. Restore the files, or "
                "delete that round's folders under rounds/ and policies/ and every later one, and "
                "resume to redo them."
            )

    def round_file_problems(self, record: RoundRecord) -> list[str]:
        """Files of a committed round that differ from its record's checksums (none recorded: [])."""
        if record.files is None:
            return []
        root = self.round_root(record.round)
        problems = digest_mismatches(root, record.files, exclude=RECORD_FILES)
        if (root / RECORD_FILE).is_file():
            info = read_committed_json(root / INFO_FILE, "restore it")
            mirror = info.get(RECORD_KEY) if isinstance(info, dict) else None
            if mirror is not None and mirror != read_committed_json(root / RECORD_FILE, "restore it"):
                problems.append(f"{root / INFO_FILE} holds a record that differs from {root / RECORD_FILE}")
        return problems

    def phase_file_problems(self, record: PhaseRecord) -> list[str]:
        """Files of a committed policy folder that differ from its record's checksums."""
        if record.files is None:
            return []
        return digest_mismatches(self.policy_root(record.round), record.files, exclude=(TRAINING_FILE,))

    def clear_staging(self) -> None:
        """Deletes what was being written when a run was cut off (a phase's saved progress is kept)."""
        for parent in (self.rounds, self.policies):
            staging = parent / STAGING_DIR
            if staging.exists():
                logger.info("Discarding unfinished work in %s", staging)
                shutil.rmtree(staging)
        for round_index in self.committed_phases():
            self.discard_phase_progress(round_index)

    # ---------------------------------------------------------------------------------------------
    # Rounds
    # ---------------------------------------------------------------------------------------------

    def round_root(self, round_index: int) -> Path:
        """Folder of a committed round."""
        return self.rounds / round_name(round_index)

    def committed_rounds(self) -> list[int]:
        """Indices of the committed rounds, ascending (``UserError`` on a folder that is not one)."""
        indices: list[int] = []
        if not self.rounds.exists():
            return indices
        for path in sorted(self.rounds.glob("round-*")):
            indices.append(self.read_round_record_at(path).round)
        expected = list(range(len(indices)))
        if indices != expected:
            raise CorruptExperimentError(
                f"Committed rounds {indices} in {self.rounds} are not consecutive from 0: restore the "
                "missing round, or delete every round after the gap (and its policies) and resume."
            )
        return indices

    @staticmethod
    def read_round_record_at(path: Path) -> RoundRecord:
        """The record of the round at ``path`` (``CorruptExperimentError`` if it holds no readable one)."""
        if (path / RECORD_FILE).is_file():
            fix = "restore it, or move the round out of the experiment directory"
            return round_record_from(read_committed_json(path / RECORD_FILE, fix), path, path / RECORD_FILE)
        return round_record_from_info(path, path / INFO_FILE)

    def read_round_record(self, round_index: int) -> RoundRecord:
        """The record of a committed round."""
        return self.read_round_record_at(self.round_root(round_index))

    def create_round(
        self, round_index: int, features: dict[str, Any], task_names: Sequence[str]
    ) -> LeRobotDataset:
        """Creates an empty round dataset in staging with the experiment's task vocabulary."""
        staging = self.rounds / STAGING_DIR / round_name(round_index)
        if staging.exists():
            shutil.rmtree(staging)
        staging.parent.mkdir(parents=True, exist_ok=True)
        with quiet_third_party():
            dataset = LeRobotDataset.create(
                repo_id=f"local/{round_name(round_index)}",
                fps=DATASET_FPS,
                features=features,
                root=staging,
                use_videos=False,
                # Rounds store images, never videos: name the decoder so that LeRobot does not probe
                # torchcodec (a multi-line warning per dataset on a machine without FFmpeg's libraries).
                video_backend=VIDEO_BACKEND,
            )
        dataset.meta.save_episode_tasks(list(task_names))
        return dataset

    def write_round(
        self,
        round_index: int,
        features: dict[str, Any],
        task_names: Sequence[str],
        episodes: Sequence[EpisodeFrames],
    ) -> LeRobotDataset:
        """Creates a round dataset in staging and writes all its episodes in one go.

        As :meth:`create_round` and ``add_frame``/``save_episode`` per frame and episode would, but much
        cheaper. Commit the returned (not finalised) dataset with :meth:`commit_round`.

        Args:
            round_index: Index of the round.
            features: The round's LeRobot features (``records.round_features``).
            task_names: The experiment's task vocabulary, in task-index order.
            episodes: ``(task, frames)`` per episode; a frame maps each non-default feature to its value.

        Raises:
            ValueError: If a frame does not match the features or an episode has no frame.
        """
        dataset = self.create_round(round_index, features, task_names)
        extra = {key for _, frames in episodes[:1] for key in (frames[0] if frames else ())} - set(features)
        if extra:  # an experiment without the provenance columns: drop them from every frame
            episodes = [(task, [_only(frame, features) for frame in frames]) for task, frames in episodes]
        write_round_episodes(dataset, episodes)
        return dataset

    def round_features(self, suite_features: dict[str, Any]) -> dict[str, Any]:
        """The features of the next round: with provenance columns unless round 0 has none (one schema)."""
        first = self.round_root(0) / INFO_FILE
        provenance = not first.is_file() or has_provenance(json.loads(first.read_text())["features"])
        return round_features(suite_features, provenance=provenance)

    def commit_round(self, round_index: int, dataset: LeRobotDataset, record: RoundRecord) -> Path:
        """Finalises a staged round, writes its record files and commits it (``FileExistsError`` if done)."""
        final = self.round_root(round_index)
        if final.exists():
            raise FileExistsError(f"Round {round_index} is already committed at {final}; it is immutable.")
        dataset.finalize()
        staging = Path(dataset.root)
        sort_stats_file(staging)
        files = folder_digests(staging, exclude=RECORD_FILES)
        committed = dataclasses.replace(
            record, format_version=FORMAT_VERSION, committed=True, files=files, ledger=True
        )
        write_record_files(staging, committed.to_dict())
        os.replace(staging, final)
        self.update_ledger()
        return final

    # ---------------------------------------------------------------------------------------------
    # Training phases
    # ---------------------------------------------------------------------------------------------

    def policy_root(self, round_index: int) -> Path:
        """Folder of the policy trained on rounds 0..round_index."""
        return self.policies / round_name(round_index)

    def committed_phases(self) -> list[int]:
        """Indices of the committed training phases, ascending."""
        if not self.policies.exists():
            return []
        return sorted(
            int(p.name.split("-")[1]) for p in self.policies.glob("round-*") if (p / TRAINING_FILE).exists()
        )

    def phase_progress_path(self, round_index: int) -> Path:
        """The saved progress of a phase being trained (``runner.training.phase_progress``)."""
        return self.policies / PROGRESS_DIR / f"{round_name(round_index)}.pt"

    def staging_policy_root(self, round_index: int) -> Path:
        """An empty staging folder for a training phase."""
        staging = self.policies / STAGING_DIR / round_name(round_index)
        if staging.exists():
            shutil.rmtree(staging)
        staging.mkdir(parents=True)
        return staging

    def commit_phase(self, round_index: int, staging: Path, record: PhaseRecord) -> Path:
        """Writes the training record (with the folder's checksums) into a staged phase and commits it."""
        files = folder_digests(staging, exclude=(TRAINING_FILE,))
        write_json_atomic(
            staging / TRAINING_FILE, dataclasses.replace(record, files=files, ledger=True).to_dict()
        )
        final = self.policy_root(round_index)
        if final.exists():
            raise FileExistsError(f"Training phase {round_index} is already committed at {final}.")
        os.replace(staging, final)
        self.update_ledger()
        self.discard_phase_progress(round_index)
        return final

    def discard_phase_progress(self, round_index: int) -> None:
        """Deletes a phase's saved progress (and one cut off while written), and its folder once empty."""
        path = self.phase_progress_path(round_index)
        path.unlink(missing_ok=True)
        path.with_name(path.name + PARTIAL_SUFFIX).unlink(missing_ok=True)
        if path.parent.is_dir() and not any(path.parent.iterdir()):
            path.parent.rmdir()

    # ---------------------------------------------------------------------------------------------
    # The ledger (datasets/ledger.py)
    # ---------------------------------------------------------------------------------------------

    def committed_record_files(self) -> list[Path]:
        """Every committed record file, in commit order (round k's, then phase k's), found by folder name."""
        rounds = {int(p.name.split("-")[1]) for p in self.rounds.glob("round-*") if p.is_dir()}
        rounds = {k for k in rounds if any((self.round_root(k) / f).is_file() for f in RECORD_FILES)}
        phases = set(self.committed_phases())
        files = []
        for k in sorted(rounds | phases):
            if k in rounds:
                root = self.round_root(k)
                files.append(root / RECORD_FILE if (root / RECORD_FILE).is_file() else root / INFO_FILE)
            if k in phases:
                files.append(self.policy_root(k) / TRAINING_FILE)
        return files

    def update_ledger(self) -> None:
        """Adds the committed records the ledger does not list yet (starting it if there is none)."""
        Ledger(self.root).append(self.committed_record_files(), write_json_atomic)

    def ledger_problems(self, resuming: bool = False) -> list[str]:
        """Records that differ from the ledger, less what a resume mends when ``resuming``."""
        records = self.committed_record_files()
        ledger = Ledger(self.root)
        if not ledger.exists():
            return self._missing_ledger_problems(records, resuming)
        problems = ledger.problems(records, deleted_tail_ok=resuming)
        return [p for p in problems if "is committed but not in" not in p] if resuming else problems

    def _missing_ledger_problems(self, records: Sequence[Path], resuming: bool) -> list[str]:
        """A missing ledger, named when a record says it was committed into one."""
        ledgered = [path for path in records if committed_into_ledger(path)]
        if not ledgered or (resuming and ledgered == list(records[-1:]) and len(records) == 1):
            return []
        first = ledgered[0].relative_to(self.root).as_posix()
        return [
            f"{self.root / LEDGER_FILE} is missing (deleted or moved), though {len(ledgered)} committed "
            f"record(s) were written into it (first: {first}): restore it from a copy of the experiment"
        ]

    def ledger_note(self) -> str | None:
        """A note for an experiment with no ledger and no record committed into one, else None."""
        records = self.committed_record_files()
        if not records or Ledger(self.root).exists() or any(committed_into_ledger(p) for p in records):
            return None
        return pre_ledger_note(self.root, LEDGER_FILE)

    def read_phase_record(self, round_index: int) -> PhaseRecord:
        """The training record of a committed phase (``CorruptExperimentError`` if unreadable)."""
        path = self.policy_root(round_index) / TRAINING_FILE
        fix = f"delete policies/{round_name(round_index)} and every later phase, and resume to retrain them"
        values = read_committed_json(path, fix)
        return PhaseRecord.from_dict(values, where=f"The training record {path}")


SAVED_RECORD_FILE = "mtdagger.json"
"""A round's ``meta/mtdagger.json`` where the saved records keep it (``rounds/<round>/``)."""

SAVED_INFO_FILE = "info.json"
"""A round's ``meta/info.json`` where the saved records keep it (rounds without ``mtdagger.json``)."""


class SavedRunRecords(ExperimentDir):
    """A run's small JSON records, saved apart from its datasets and weights, read as a run is read.

    The layout ``lerobot-mtdagger records --action=save`` writes; enough to report the run, not to
    verify, resume, merge or push it::

        <run>/config.json                       the run's options
        <run>/rounds/round-000/mtdagger.json    the round's record (or info.json with it)
        <run>/policies/round-000/training.json  the phase's training record, evaluation included
    """

    @staticmethod
    def read_round_record_at(path: Path) -> RoundRecord:
        """The record of the saved round at ``path`` (``CorruptExperimentError`` if none is readable)."""
        if (path / SAVED_RECORD_FILE).is_file():
            fix = "save the run's records again"
            record = read_committed_json(path / SAVED_RECORD_FILE, fix)
            return round_record_from(record, path, path / SAVED_RECORD_FILE)
        return round_record_from_info(path, path / SAVED_INFO_FILE)


def is_saved_records(root: Path) -> bool:
    """Whether ``root`` holds a run's saved records (``SavedRunRecords``) rather than a run folder."""
    first_round = Path(root) / ROUNDS_DIR / round_name(0)
    saved = (first_round / SAVED_RECORD_FILE).is_file() or (first_round / SAVED_INFO_FILE).is_file()
    return saved and not (first_round / INFO_FILE).is_file()


def open_run(root: Path) -> ExperimentDir:
    """The run folder or the saved records (``SavedRunRecords``) at ``root``, to read."""
    return SavedRunRecords(root) if is_saved_records(root) else ExperimentDir(root)


def sort_stats_file(root: Path) -> None:
    """Rewrites ``meta/stats.json`` with sorted keys, so a round's bytes are reproducible."""
    path = root / STATS_FILE
    if path.is_file():
        stats = json.loads(path.read_text())
        path.write_text(json.dumps(stats, indent=4, ensure_ascii=False, sort_keys=True))


RENUMBERED_COLUMNS = ("episode_index", "index", "task_index")
"""The columns LeRobot's ``update_data_df`` renumbers when it aggregates datasets."""


@contextlib.contextmanager
def _data_files_merged_in_arrow(features: Mapping[str, Mapping[str, Any]]) -> Iterator[None]:
    """Lets LeRobot 0.4's ``aggregate_datasets`` merge data files with 2-D features, in Arrow."""
    from lerobot.datasets import aggregate
    from lerobot.datasets.utils import DEFAULT_DATA_PATH

    if not any(
        len(spec["shape"]) > 1 and spec["dtype"] not in ("image", "video") for spec in features.values()
    ):
        yield
        return
    original = aggregate.append_or_create_parquet_file

    def write(df: Any, src_path: Path, idx: dict[str, int], *args: Any, **kwargs: Any) -> Any:
        max_mb, chunk_size, default_path = args[:3]
        if default_path != DEFAULT_DATA_PATH:
            return original(df, src_path, idx, *args, **kwargs)
        return _append_data_file(df, src_path, idx, max_mb, chunk_size, kwargs["aggr_root"] / default_path)

    aggregate.append_or_create_parquet_file = write
    try:
        yield
    finally:
        aggregate.append_or_create_parquet_file = original


def _append_data_file(
    df: Any, src_path: Path, idx: dict[str, int], max_mb: float, chunk_size: int, path_format: Path
) -> tuple[dict[str, int], tuple[int, int]]:
    """``append_or_create_parquet_file`` for data files, in Arrow (same file rotation rule).

    Returns:
        ``idx`` (the destination's ``chunk`` and ``file``, updated) and the (chunk, file) written to.
    """
    table = pq.read_table(src_path)
    for name in RENUMBERED_COLUMNS:
        if name in df.columns:
            column = table.schema.get_field_index(name)
            values = pa.array(df[name].to_numpy(), type=table.schema.field(name).type)
            table = table.set_column(column, table.schema.field(name), values)
    path = Path(str(path_format).format(chunk_index=idx["chunk"], file_index=idx["file"]))
    if path.exists():
        if path.stat().st_size + src_path.stat().st_size >= max_mb * 1024 * 1024:
            idx["chunk"], idx["file"] = update_chunk_file_indices(idx["chunk"], idx["file"], chunk_size)
            path = Path(str(path_format).format(chunk_index=idx["chunk"], file_index=idx["file"]))
        else:
            table = pa.concat_tables([pq.read_table(path), table])
    path.parent.mkdir(parents=True, exist_ok=True)
    pq.write_table(table, path)
    return idx, (idx["chunk"], idx["file"])


def merge_rounds(
    experiment: ExperimentDir,
    rounds: Sequence[int],
    output: Path,
    repo_id: str = "local/merged",
    unverified: Sequence[str] = (),
) -> Path:
    """Merges round datasets into one LeRobotDataset with LeRobot's own aggregation, task indices kept.

    Its ``mtdagger`` record lists the rounds' records and ``unverified`` (problems the caller read
    past). It is written beside ``output`` and renamed onto it when complete.

    Raises:
        UserError: If ``output`` exists.
        CorruptExperimentError: If a round's files changed after commit (before anything is written).
    """
    from lerobot.datasets.aggregate import aggregate_datasets

    if output.exists():
        raise UserError(f"Merge target {output} exists; choose another --output or delete it.")
    records = [experiment.read_round_record(k) for k in rounds]
    problems = [problem for record in records for problem in experiment.round_file_problems(record)]
    if problems and not unverified:
        raise CorruptExperimentError(f"Cannot merge: {'; '.join(problems)}. Restore the files first.")
    staging = output.parent / f".{output.name}.merging"
    if staging.exists():
        shutil.rmtree(staging)
    features = json.loads((experiment.round_root(rounds[0]) / INFO_FILE).read_text())["features"]
    with quiet_third_party(), _data_files_merged_in_arrow(features):
        aggregate_datasets(
            repo_ids=[f"local/{round_name(k)}" for k in rounds],
            aggr_repo_id=repo_id,
            roots=[experiment.round_root(k) for k in rounds],
            aggr_root=staging,
        )
    merged = {
        "format_version": FORMAT_VERSION,
        "merged_rounds": list(rounds),
        "rounds": [record.to_dict() for record in records],
    }
    if unverified:
        merged["unverified"] = list(unverified)
    write_record_files(staging, merged)
    os.replace(staging, output)
    return output
