"""The episodes of a LeRobot dataset, as ``plan`` counts them: task, success, and who acted.

Any LeRobot v3.0 dataset is read (``lerobot-record``, ``lerobot-rollout``, ``lerobot-eval``'s, a round
of a run): its metadata through LeRobot's ``LeRobotDatasetMetadata``, the few frame columns ``plan``
needs straight from its parquet files (no video is decoded). An episode's

- task is its first frame's task (LeRobot's task string);
- success is whether any frame has ``next.success`` (as ``lerobot-eval`` records it), or the named
  ``--success_key`` (a frame column, or a column of ``meta/episodes``, e.g. a run's ``success``), or
  the operator's label in ``--success_labels`` (LeRobot's rollouts on a real robot record no success);
- policy episode: no frame has the intervention column (``intervention``, as LeRobot 0.6's DAgger
  rollouts record it) set. Success while a person took over is not the policy's: a run's task need
  counts only episodes where the learner acted alone, and so does ``plan``.
"""

from __future__ import annotations

import hashlib
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq

from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.hub import check_hub_repo, is_hub_id, lerobot_dataset_cache, network_errors

FRAME_SUCCESS_KEY = "next.success"
"""The per-frame success column ``lerobot-eval`` and the runner's rounds write."""
EPISODE_SUCCESS_KEY = "success"
"""The per-episode success column of a run's rounds (``meta/episodes``)."""
INTERVENTION_KEY = "intervention"
"""LeRobot 0.6's DAgger rollouts: True on the frames a person controlled."""


@dataclass(frozen=True)
class DatasetEpisodes:
    """What ``plan`` read from one dataset.

    Attributes:
        source: The dataset as given (a local folder or a Hub repo id).
        root: The local folder it was read from.
        checksum: sha256 over its ``data/`` and ``meta/`` files (names and bytes): a later
            ``plan --verify`` names a dataset that changed.
        revision: The Hub revision it was read at (a repo id), else None.
        fps: Frames per second.
        success_key: Where success was read: ``frames:<column>`` or ``episodes:<column>``.
        intervention_key: The intervention column read, or None (the dataset has none: every episode
            is the policy's alone).
        episodes: Episode indices, in order.
        tasks: Each episode's task.
        success: Each episode's success.
        policy_only: Whether the policy acted alone in each episode.
        seconds: Each episode's duration (frames / fps).
    """

    source: str
    root: str
    checksum: str
    revision: str | None
    fps: float
    success_key: str
    intervention_key: str | None
    episodes: tuple[int, ...]
    tasks: tuple[str, ...]
    success: tuple[bool, ...]
    policy_only: tuple[bool, ...]
    seconds: tuple[float, ...]

    def to_dict(self) -> dict:
        """The JSON record kept in the plan file."""
        return {
            "source": self.source,
            "root": self.root,
            "checksum": self.checksum,
            "revision": self.revision,
            "fps": self.fps,
            "success_key": self.success_key,
            "intervention_key": self.intervention_key,
            "episodes": list(self.episodes),
            "tasks": list(self.tasks),
            "success": list(self.success),
            "policy_only": list(self.policy_only),
            "seconds": list(self.seconds),
        }


def dataset_checksum(root: Path) -> str:
    """sha256 over the relative names and bytes of every file under ``root/data`` and ``root/meta``."""
    hasher = hashlib.sha256()
    for path in sorted(p for folder in ("data", "meta") for p in (root / folder).rglob("*") if p.is_file()):
        hasher.update(path.relative_to(root).as_posix().encode() + b"\0")
        hasher.update(hashlib.sha256(path.read_bytes()).digest())
    return hasher.hexdigest()


def check_dataset_source(source: str, option: str = "--datasets") -> None:
    """Refuses a dataset that is neither a LeRobot dataset folder nor a repo id LeRobot can read.

    A repo id in LeRobot's cache (``$HF_LEROBOT_HOME/<repo_id>``) is read from there; any other is
    looked up on the Hub once, without retries (``utils.hub``), before LeRobot is imported.

    Raises:
        UserError: In one line naming the dataset and the fix.
    """
    _check_local_source(source, option)
    if not Path(source).expanduser().exists():
        cached = (lerobot_dataset_cache(source) / "meta" / "info.json").is_file()
        check_hub_repo(source, "dataset", option, cached)


def _check_local_source(source: str, option: str) -> None:
    """Refuses a folder that is not a LeRobot dataset, and a missing path that is not a repo id."""
    path = Path(source).expanduser()
    if path.exists() and not (path / "meta" / "info.json").is_file():
        raise UserError(
            f"{option}: {source} is not a LeRobot dataset (no meta/info.json): give the folder "
            "lerobot-record or lerobot-rollout wrote (its --dataset.root), or a Hub repo id."
        )
    if not path.exists() and not is_hub_id(source):
        raise UserError(
            f"{option}: {source} is neither a folder nor a Hub repo id (user/name): give the "
            "dataset's local folder or its repo id."
        )


def open_metadata(source: str, revision: str | None = None):
    """LeRobot's metadata of a local dataset folder or a Hub repo id (read from LeRobot's cache first).

    Raises:
        UserError: If it is neither a LeRobot dataset folder nor a repo id LeRobot can open.
    """
    from lerobot.datasets.lerobot_dataset import LeRobotDatasetMetadata

    _check_local_source(source, "--datasets")
    path = Path(source).expanduser()
    if path.exists():
        return LeRobotDatasetMetadata(f"local/{path.name}", root=path)
    try:
        return LeRobotDatasetMetadata(source, revision=revision)
    except (OSError, ValueError) + network_errors() as error:  # network, missing repo, or a bad revision
        raise UserError(
            f"--datasets: cannot open {source} from the Hub or LeRobot's cache ({type(error).__name__}): "
            "check the repo id and your connection, or give its local folder."
        ) from None


def read_dataset(
    source: str,
    success_key: str | None,
    intervention_key: str | None,
    labels: dict[int, bool] | None = None,
) -> DatasetEpisodes:
    """Reads one dataset's episodes (see the module docstring for the rules).

    Args:
        source: A local dataset folder or a Hub repo id.
        success_key: The success column (frames or ``meta/episodes``); None: ``next.success`` in the
            frames, else ``success`` in ``meta/episodes``.
        intervention_key: The intervention column; a dataset without it has only policy episodes.
        labels: The operator's success label of every episode (``--success_labels``), instead of a
            column.

    Raises:
        UserError: On a dataset without task labels or without any success signal, or labels that
            miss an episode (one line each).
    """
    meta = open_metadata(source)
    root = Path(meta.root)
    task_names = _task_names(meta, source)
    episode_columns = set(meta.episodes.column_names)
    if labels is not None:
        success_where = ("labels", "--success_labels")
    else:
        success_where = _success_column(meta, source, success_key, episode_columns)
    frame_columns = ["episode_index", "task_index"]
    if success_where[0] == "frames":
        frame_columns.append(success_where[1])
    intervention = intervention_key if intervention_key in meta.features else None
    if intervention is not None:
        frame_columns.append(intervention)
    frames = _frame_columns(root, frame_columns)
    episodes = [int(e) for e in meta.episodes["episode_index"]]
    lengths = dict(zip(episodes, (int(n) for n in meta.episodes["length"]), strict=True))
    by_episode = _split_by_episode(frames["episode_index"])
    missing = [e for e in episodes if e not in by_episode]
    if missing:
        raise UserError(
            f"--datasets: {source} lists episodes {missing[:5]} with no frames: it is incomplete."
        )
    tasks, success, policy_only = [], [], []
    episode_success = None
    if success_where[0] == "episodes":
        episode_success = dict(zip(episodes, meta.episodes[success_where[1]], strict=True))
    elif labels is not None:
        unlabelled = [e for e in episodes if e not in labels]
        if unlabelled:
            raise UserError(
                f"--success_labels has no label for episode(s) {unlabelled[:10]} of {source}: label every "
                "episode of the dataset (true or false)."
            )
        episode_success = labels
    for episode in episodes:
        rows = by_episode[episode]
        tasks.append(task_names[int(frames["task_index"][rows[0]])])
        if episode_success is not None:
            success.append(bool(episode_success[episode]))
        else:
            success.append(bool(np.any(frames[success_where[1]][rows])))
        policy_only.append(True if intervention is None else not bool(np.any(frames[intervention][rows])))
    fps = float(meta.fps)
    return DatasetEpisodes(
        source=source,
        root=str(root),
        checksum=dataset_checksum(root),
        revision=None if Path(source).expanduser().exists() else str(meta.revision),
        fps=fps,
        success_key=":".join(success_where),
        intervention_key=intervention,
        episodes=tuple(episodes),
        tasks=tuple(tasks),
        success=tuple(success),
        policy_only=tuple(policy_only),
        seconds=tuple(lengths[e] / fps for e in episodes),
    )


def _task_names(meta, source: str) -> dict[int, str]:
    """task_index -> task string; refuses a dataset without task labels."""
    names = {
        int(index): str(task) for task, index in zip(meta.tasks.index, meta.tasks["task_index"], strict=True)
    }
    if not names or all(not name.strip() for name in names.values()):
        raise UserError(
            f"--datasets: {source} has no task labels: plan allocates per task, so record each episode with "
            "its task (lerobot-record --dataset.single_task=...)."
        )
    return names


def _success_column(meta, source: str, success_key: str | None, episode_columns: set[str]) -> tuple[str, str]:
    """``("frames", column)`` or ``("episodes", column)``: where the episodes' success is read."""
    if success_key is None:
        if FRAME_SUCCESS_KEY in meta.features:
            return "frames", FRAME_SUCCESS_KEY
        if EPISODE_SUCCESS_KEY in episode_columns:
            return "episodes", EPISODE_SUCCESS_KEY
    elif success_key in meta.features:
        return "frames", success_key
    elif success_key in episode_columns:
        return "episodes", success_key
    looked = (
        f"'{success_key}'"
        if success_key
        else f"'{FRAME_SUCCESS_KEY}' (frames) or '{EPISODE_SUCCESS_KEY}' (episodes)"
    )
    raise UserError(
        f"--datasets: {source} has no success signal: no column {looked}. Record success per frame "
        f"(next.success, as lerobot-eval does) or name the column that holds it with --success_key "
        f"(its frame columns: {', '.join(sorted(meta.features))})."
    )


def _frame_columns(root: Path, columns: Sequence[str]) -> dict[str, np.ndarray]:
    """The named columns of every frame under ``root/data``, in file order, as flat arrays."""
    files = sorted((root / "data").glob("*/*.parquet"))
    tables = [pq.read_table(path, columns=list(columns)) for path in files]
    out: dict[str, np.ndarray] = {}
    for column in columns:
        values = [np.asarray(table.column(column).to_pylist(), dtype=object) for table in tables]
        joined = np.concatenate(values) if values else np.array([], dtype=object)
        out[column] = np.array([_scalar(v) for v in joined])
    return out


def _scalar(value: object) -> object:
    """A frame's value: LeRobot stores shape-(1,) features as one-element lists."""
    return value[0] if isinstance(value, list) and len(value) == 1 else value


def _split_by_episode(episode_index: np.ndarray) -> dict[int, np.ndarray]:
    """Frame rows of each episode."""
    order = episode_index.astype(np.int64)
    return {int(e): np.flatnonzero(order == e) for e in np.unique(order)}
