"""Round datasets and training phases of a Multitask DAgger experiment, on disk.

Layout of an experiment directory::

    <output_dir>/
        config.json                  the run config (written once; a resume must match it)
        run.log                      log of every run and resume
        rounds/
            round-000/               LeRobotDataset v3.0 of round 0 (expert demonstrations)
                meta/info.json       ... "mtdagger": the round's record (allocation, Kalman state, ...)
            round-001/               LeRobotDataset of round 1 (DAgger rollouts, expert labels)
            .staging/round-002/      a round being written: never read, deleted on resume
        policies/
            round-000/               policy trained on rounds 0..0 (LeRobot pretrained model +
                                     processors) and training.json (per-task losses, gain, eval)
            .staging/round-001/      a training phase being written

A round or training phase is committed by an atomic rename of its finished staging folder; anything
cut off half-way stays in ``.staging`` and is discarded, so a committed round is immutable and
complete. Every round dataset carries the experiment's full task vocabulary in the same order
(``meta.save_episode_tasks(task_names)`` right after creation), so task_index i is the same task in
every round and in merged datasets.
"""

from __future__ import annotations

import dataclasses
import json
import logging
import os
import shutil
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lerobot.datasets.lerobot_dataset import LeRobotDataset

from lerobot_mtdagger.records import FORMAT_VERSION, RECORD_KEY, PhaseRecord, RoundRecord

logger = logging.getLogger(__name__)

ROUNDS_DIR = "rounds"
POLICIES_DIR = "policies"
STAGING_DIR = ".staging"
TRAINING_FILE = "training.json"
CONFIG_FILE = "config.json"
DATASET_FPS = 80


def round_name(round_index: int) -> str:
    """Folder and Hub revision name of a round: ``round-{k:03d}``."""
    return f"round-{round_index:03d}"


def write_json_atomic(path: Path, payload: Any) -> None:
    """Writes JSON to ``path`` through a temporary file and an atomic rename."""
    tmp = path.with_suffix(path.suffix + ".tmp")
    tmp.write_text(json.dumps(payload, indent=2, allow_nan=False))
    os.replace(tmp, path)


class ExperimentDir:
    """The on-disk state of one experiment (see the module docstring for the layout)."""

    def __init__(self, root: Path) -> None:
        """Points at ``root`` (nothing is created)."""
        self.root = Path(root)
        self.rounds = self.root / ROUNDS_DIR
        self.policies = self.root / POLICIES_DIR

    # ---------------------------------------------------------------------------------------------
    # Creation and checks
    # ---------------------------------------------------------------------------------------------

    def exists(self) -> bool:
        """Whether the directory exists and is not empty."""
        return self.root.exists() and any(self.root.iterdir())

    def initialise(self, config: dict[str, Any]) -> None:
        """Creates the folders and writes the run config.

        Raises:
            FileExistsError: If the directory exists and is not empty.
        """
        if self.exists():
            raise FileExistsError(
                f"Output directory {self.root} already exists and is not empty: pass --resume=true to "
                "continue that experiment, or choose another --output_dir."
            )
        self.rounds.mkdir(parents=True, exist_ok=True)
        self.policies.mkdir(parents=True, exist_ok=True)
        write_json_atomic(self.root / CONFIG_FILE, config)

    def check_resumable(
        self, config: dict[str, Any], ignore: Sequence[str] = ("resume", "progress", "output_dir", "workers")
    ) -> None:
        """Checks that ``root`` holds an experiment started with the same config.

        Raises:
            FileNotFoundError: If there is no experiment to resume.
            ValueError: If the directory is not an experiment or its config differs.
        """
        config_path = self.root / CONFIG_FILE
        if not self.root.exists():
            raise FileNotFoundError(
                f"Nothing to resume: {self.root} does not exist (drop --resume to start)."
            )
        if not config_path.exists():
            raise ValueError(
                f"{self.root} is not a lerobot-mtdagger experiment (no {CONFIG_FILE}); it was left untouched."
            )
        stored = json.loads(config_path.read_text())
        differing = sorted(
            key
            for key in set(stored) | set(config)
            if key not in ignore and stored.get(key) != config.get(key)
        )
        if differing:
            details = ", ".join(f"{k}: {stored.get(k)!r} -> {config.get(k)!r}" for k in differing)
            raise ValueError(f"Cannot resume {self.root} with a different config ({details}).")

    def clear_staging(self) -> None:
        """Deletes everything that was being written when a run was cut off."""
        for parent in (self.rounds, self.policies):
            staging = parent / STAGING_DIR
            if staging.exists():
                logger.info("Discarding unfinished work in %s", staging)
                shutil.rmtree(staging)

    # ---------------------------------------------------------------------------------------------
    # Rounds
    # ---------------------------------------------------------------------------------------------

    def round_root(self, round_index: int) -> Path:
        """Folder of a committed round."""
        return self.rounds / round_name(round_index)

    def committed_rounds(self) -> list[int]:
        """Indices of the committed rounds, ascending.

        Raises:
            ValueError: If a round folder is not a committed round of this format (a foreign or
                corrupt dataset in the output directory).
        """
        indices = []
        if not self.rounds.exists():
            return indices
        for path in sorted(self.rounds.glob("round-*")):
            indices.append(self.read_round_record_at(path).round)
        expected = list(range(len(indices)))
        if indices != expected:
            raise ValueError(f"Committed rounds {indices} in {self.rounds} are not consecutive from 0.")
        return indices

    @staticmethod
    def read_round_record_at(path: Path) -> RoundRecord:
        """The ``mtdagger`` record of the round dataset at ``path``.

        Raises:
            ValueError: If ``path`` holds no readable round record.
        """
        info_path = path / "meta" / "info.json"
        try:
            info = json.loads(info_path.read_text())
        except (OSError, json.JSONDecodeError) as error:
            raise ValueError(f"{path} is not a readable round dataset ({info_path}: {error}).") from error
        record = info.get(RECORD_KEY)
        if not isinstance(record, dict) or record.get("format_version") != FORMAT_VERSION:
            raise ValueError(
                f"{path} is not a lerobot-mtdagger round (no '{RECORD_KEY}' record of format "
                f"{FORMAT_VERSION} in {info_path}); move it out of the experiment directory."
            )
        if not record.get("committed"):
            raise ValueError(f"{path} holds an uncommitted round record.")
        return RoundRecord.from_dict(record, where=f"The round record in {info_path}")

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
        dataset = LeRobotDataset.create(
            repo_id=f"local/{round_name(round_index)}",
            fps=DATASET_FPS,
            features=features,
            root=staging,
            use_videos=False,
        )
        dataset.meta.save_episode_tasks(list(task_names))
        return dataset

    def commit_round(self, round_index: int, dataset: LeRobotDataset, record: RoundRecord) -> Path:
        """Finalises a staged round, writes its record into meta/info.json and commits it atomically.

        Raises:
            FileExistsError: If the round is already committed (a committed round is immutable).
        """
        final = self.round_root(round_index)
        if final.exists():
            raise FileExistsError(f"Round {round_index} is already committed at {final}; it is immutable.")
        dataset.finalize()
        staging = Path(dataset.root)
        info_path = staging / "meta" / "info.json"
        info = json.loads(info_path.read_text())
        info[RECORD_KEY] = dataclasses.replace(
            record, format_version=FORMAT_VERSION, committed=True
        ).to_dict()
        write_json_atomic(info_path, info)
        os.replace(staging, final)
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

    def staging_policy_root(self, round_index: int) -> Path:
        """An empty staging folder for a training phase."""
        staging = self.policies / STAGING_DIR / round_name(round_index)
        if staging.exists():
            shutil.rmtree(staging)
        staging.mkdir(parents=True)
        return staging

    def commit_phase(self, round_index: int, staging: Path, record: PhaseRecord) -> Path:
        """Writes the training record into a staged phase and commits it atomically."""
        write_json_atomic(staging / TRAINING_FILE, record.to_dict())
        final = self.policy_root(round_index)
        if final.exists():
            raise FileExistsError(f"Training phase {round_index} is already committed at {final}.")
        os.replace(staging, final)
        return final

    def read_phase_record(self, round_index: int) -> PhaseRecord:
        """The training record of a committed phase."""
        path = self.policy_root(round_index) / TRAINING_FILE
        return PhaseRecord.from_dict(json.loads(path.read_text()), where=f"The training record {path}")


def merge_rounds(
    experiment: ExperimentDir, rounds: Sequence[int], output: Path, repo_id: str = "local/merged"
) -> Path:
    """Merges round datasets into ONE LeRobotDataset with LeRobot's own aggregation.

    Task indices are preserved: every round holds the full vocabulary in the same order. The merged
    dataset's meta/info.json gets a ``mtdagger`` record listing the merged rounds' records.

    Raises:
        FileExistsError: If ``output`` exists.
        ValueError: If a round is not committed.
    """
    from lerobot.datasets.aggregate import aggregate_datasets

    if output.exists():
        raise FileExistsError(f"Merge target {output} exists; choose another path.")
    records = [experiment.read_round_record(k) for k in rounds]
    roots = [experiment.round_root(k) for k in rounds]
    aggregate_datasets(
        repo_ids=[f"local/{round_name(k)}" for k in rounds],
        aggr_repo_id=repo_id,
        roots=roots,
        aggr_root=output,
    )
    info_path = output / "meta" / "info.json"
    info = json.loads(info_path.read_text())
    info[RECORD_KEY] = {
        "format_version": FORMAT_VERSION,
        "merged_rounds": list(rounds),
        "rounds": [record.to_dict() for record in records],
    }
    write_json_atomic(info_path, info)
    return output
