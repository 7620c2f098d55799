"""The one-go round writer (``ExperimentDir.write_round``): the same dataset as LeRobot's own
``add_frame`` / ``save_episode`` loop, much cheaper.
"""

from __future__ import annotations

import json
import logging
import warnings
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, round_name
from lerobot_mtdagger.datasets.records import StepOutcome, dagger_columns, round_features
from lerobot_mtdagger.datasets.round_writer import _vector_episode_stats, save_episode_with_success
from lerobot_mtdagger.utils.quiet import quiet_third_party

TASKS = ["task a", "task b", "task c"]


def _features(pointcloud: bool = True) -> dict:
    suite = {"observation.state": {"dtype": "float32", "shape": (39,), "names": [f"s{i}" for i in range(39)]}}
    if pointcloud:
        suite["observation.environment_state"] = {
            "dtype": "float32",
            "shape": (8, 6),
            "names": ["points", "channels"],
        }
    suite["action"] = {"dtype": "float32", "shape": (4,), "names": ["x", "y", "z", "g"]}
    return round_features(suite)


def _episodes(rng, lengths, pointcloud: bool = True, round_index: int = 1) -> list:
    episodes = []
    for e, length in enumerate(lengths):
        frames = []
        for t in range(length):
            frame = {
                "observation.state": rng.standard_normal(39).astype(np.float32),
                "action": np.array([0.5, -1.0, t, 0.0], dtype=np.float32),  # constant and ramp columns
                **dagger_columns(
                    rng.standard_normal(4),
                    bool(rng.random() < 0.5),
                    round_index,
                    StepOutcome(float(rng.random()), t == length - 1, t == length - 1),
                ),
            }
            if pointcloud:
                frame["observation.environment_state"] = rng.standard_normal((8, 6)).astype(np.float32)
            frames.append(frame)
        episodes.append((TASKS[e % len(TASKS)], frames))
    return episodes


def _record_stub():
    from lerobot_mtdagger.datasets.records import RoundRecord

    blank = dict.fromkeys(("success_rate", "episodes", "gain", "metric", "score", "probability"))
    return RoundRecord(
        task_names=TASKS,
        round=0,
        method="need",
        beta=1.0,
        seed=0,
        budget=0,
        temperature=1.0,
        n_min=1,
        episodes_per_task=[0, 0, 0],
        demos_so_far=[0, 0, 0],
        rollout_success=None,
        rollout_episodes=[0, 0, 0],
        expert_success=None,
        learner_steps=0,
        frames=0,
        config={},
        kalman_prior={"p": None, "P": None},
        kalman_posterior={"p": None, "P": None},
        eval_success=None,
        allocation=None,
        scheduler_state=None,
        notes=[],
        **blank,
    )


def _write_with_lerobot_loop(experiment: ExperimentDir, round_index: int, features, episodes) -> Path:
    dataset = experiment.create_round(round_index, features, TASKS)
    with quiet_third_party():
        for task, frames in episodes:
            for frame in frames:
                dataset.add_frame({**frame, "task": task})
            save_episode_with_success(dataset, frames)  # LeRobot's save_episode, success in meta/episodes
    return experiment.commit_round(round_index, dataset, _record_stub())


def _without_fingerprint(schema_metadata: dict | None) -> dict | None:
    # ``datasets`` stores a random per-Dataset cache fingerprint in the schema metadata: it differs
    # between any two writes, LeRobot's own included, and is never read back.
    if not schema_metadata or b"huggingface" not in schema_metadata:
        return schema_metadata
    info = json.loads(schema_metadata[b"huggingface"])
    info.pop("fingerprint", None)
    return {**schema_metadata, b"huggingface": info}


def _assert_same_dataset_files(ours: Path, theirs: Path) -> None:
    files = sorted(p.relative_to(theirs) for p in theirs.rglob("*") if p.is_file())
    assert sorted(p.relative_to(ours) for p in ours.rglob("*") if p.is_file()) == files
    for relative in files:
        a, b = ours / relative, theirs / relative
        if relative.suffix == ".parquet":
            table_a, table_b = pq.read_table(a), pq.read_table(b)
            assert table_a.schema.equals(table_b.schema), relative
            assert _without_fingerprint(table_a.schema.metadata) == _without_fingerprint(
                table_b.schema.metadata
            )
            assert table_a.equals(table_b), relative
            assert pq.ParquetFile(a).metadata.num_row_groups == pq.ParquetFile(b).metadata.num_row_groups
        elif relative.name == "info.json":
            ours_info, theirs_info = json.loads(a.read_text()), json.loads(b.read_text())
            # The records' sha256 of the files differ with the parquet fingerprints (see above).
            for info in (ours_info, theirs_info):
                info.get("mtdagger", {}).pop("files", None)
            assert ours_info == theirs_info, relative
        elif relative.name == "mtdagger.json":  # the record itself, the same sha256s aside
            ours_record, theirs_record = json.loads(a.read_text()), json.loads(b.read_text())
            ours_record.pop("files"), theirs_record.pop("files")
            assert ours_record == theirs_record, relative
        else:
            assert a.read_bytes() == b.read_bytes(), relative


@pytest.mark.parametrize("pointcloud", [True, False])
def test_write_round_writes_what_lerobots_loop_writes(tmp_path, pointcloud):
    rng = np.random.default_rng(0)
    # LeRobot itself cannot store a one-frame episode of a 2-D feature (its stats shapes disagree).
    lengths = [2, 5, 37, 80, 3, 2] if pointcloud else [1, 2, 5, 37, 80, 3]
    episodes = _episodes(rng, lengths, pointcloud)
    features = _features(pointcloud)
    theirs = _write_with_lerobot_loop(ExperimentDir(tmp_path / "theirs"), 0, features, episodes)
    ours_dir = ExperimentDir(tmp_path / "ours")
    ours = ours_dir.commit_round(0, ours_dir.write_round(0, features, TASKS, episodes), _record_stub())
    _assert_same_dataset_files(ours, theirs)


@pytest.mark.parametrize("failure", ["different", "broken"])
def test_write_round_falls_back_to_lerobots_stats_if_the_fast_ones_differ(
    tmp_path, monkeypatch, caplog, failure
):
    from lerobot_mtdagger.datasets import round_writer as rounds

    fast = rounds._vector_episode_stats

    def off_by_a_bit(buffer, features):
        if failure == "broken":
            raise AttributeError("'RunningQuantileStats' object has no attribute '_histograms'")
        stats = fast(buffer, features)
        stats["action"]["q50"] = stats["action"]["q50"] + 1e-9
        return stats

    monkeypatch.setattr(rounds, "_vector_episode_stats", off_by_a_bit)
    episodes = _episodes(np.random.default_rng(6), [5, 7, 3])
    theirs = _write_with_lerobot_loop(ExperimentDir(tmp_path / "theirs"), 0, _features(), episodes)
    ours_dir = ExperimentDir(tmp_path / "ours")
    with caplog.at_level(logging.WARNING, logger="lerobot_mtdagger.datasets.experiment_dir"):
        ours = ours_dir.commit_round(0, ours_dir.write_round(0, _features(), TASKS, episodes), _record_stub())
    assert "do not match this LeRobot version" in caplog.text
    _assert_same_dataset_files(ours, theirs)


def test_write_round_is_loaded_and_merged_like_lerobots(tmp_path, root_records):
    from lerobot.datasets.aggregate import aggregate_datasets
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    rng = np.random.default_rng(1)
    # State only: LeRobot's aggregate_datasets fails on 2-D (Array2D) features, its own rounds included.
    rounds = [_episodes(rng, [4, 9, 6], pointcloud=False, round_index=k) for k in range(2)]
    features = _features(pointcloud=False)
    theirs, ours = ExperimentDir(tmp_path / "theirs"), ExperimentDir(tmp_path / "ours")
    for k, episodes in enumerate(rounds):
        _write_with_lerobot_loop(theirs, k, features, episodes)
        ours.commit_round(k, ours.write_round(k, features, TASKS, episodes), _record_stub())
    with quiet_third_party():
        for k in range(2):
            a = LeRobotDataset(f"local/{round_name(k)}", root=ours.round_root(k))
            b = LeRobotDataset(f"local/{round_name(k)}", root=theirs.round_root(k))
            assert len(a) == len(b) == sum(len(f) for _, f in rounds[k])
            for i in (0, len(a) // 2, len(a) - 1):
                item_a, item_b = a[i], b[i]
                assert item_a.keys() == item_b.keys()
                for key, value in item_a.items():
                    if isinstance(value, str):
                        assert value == item_b[key]
                    else:
                        np.testing.assert_array_equal(np.asarray(value), np.asarray(item_b[key]), err_msg=key)
        for experiment, name in ((ours, "ours_merged"), (theirs, "theirs_merged")):
            aggregate_datasets(
                repo_ids=[f"local/{round_name(k)}" for k in range(2)],
                aggr_repo_id=f"local/{name}",
                roots=[experiment.round_root(k) for k in range(2)],
                aggr_root=tmp_path / name,
            )
    _assert_same_dataset_files(tmp_path / "ours_merged", tmp_path / "theirs_merged")
    assert not [m for m in root_records.messages if m.startswith("root:")], "LeRobot's step logs dropped"


def test_write_round_starts_a_new_data_file_at_the_size_limit(tmp_path):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_mtdagger.datasets.round_writer import write_round_episodes

    experiment = ExperimentDir(tmp_path)
    episodes = _episodes(np.random.default_rng(2), [50, 50, 50, 50])
    dataset = experiment.create_round(0, _features(), TASKS)
    dataset.meta.info["data_files_size_in_mb"] = 0.05  # ~ one episode (50 frames * ~1 kB) per file
    write_round_episodes(dataset, episodes)
    root = experiment.commit_round(0, dataset, _record_stub())
    assert len(list((root / "data").rglob("*.parquet"))) > 1
    with quiet_third_party():
        loaded = LeRobotDataset("local/round-000", root=root)
    assert len(loaded) == 200 and loaded.meta.total_episodes == 4
    states = np.concatenate([np.stack([f["observation.state"] for f in frames]) for _, frames in episodes])
    np.testing.assert_array_equal(
        np.stack(loaded.hf_dataset.with_format("numpy")["observation.state"]), states
    )
    for episode in range(4):
        assert loaded[episode * 50]["episode_index"] == episode and loaded[episode * 50]["frame_index"] == 0


def test_write_round_with_images_takes_lerobots_path_quietly(tmp_path, capfd):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    rng = np.random.default_rng(5)
    features = round_features(
        {
            "observation.image": {
                "dtype": "image",
                "shape": (8, 8, 3),
                "names": ["height", "width", "channels"],
            },
            "action": {"dtype": "float32", "shape": (2,), "names": ["x", "y"]},
        }
    )
    episodes = [
        (
            task,
            [
                {
                    "observation.image": rng.integers(0, 255, (8, 8, 3), dtype=np.uint8),
                    "action": rng.standard_normal(2).astype(np.float32),
                    **dagger_columns(rng.standard_normal(2), True, 1, StepOutcome(0.0, False, False)),
                }
                for _ in range(3)
            ],
        )
        for task in TASKS[:2]
    ]
    experiment = ExperimentDir(tmp_path)
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # LeRobot's stats on the bool flag
        # numpy >= 2.5 raises where 2.2 warns: a one-value column handed to datasets as (N, 1) rows
        warnings.filterwarnings("error", "Conversion of an array with ndim > 0", DeprecationWarning)
        root = experiment.commit_round(
            0, experiment.write_round(0, features, TASKS, episodes), _record_stub()
        )
    assert "Map" not in capfd.readouterr().err
    with quiet_third_party():
        loaded = LeRobotDataset("local/round-000", root=root)
    assert len(loaded) == 6 and loaded[4]["task"] == TASKS[1]
    image = (loaded[4]["observation.image"].numpy().transpose(1, 2, 0) * 255).round().astype(np.uint8)
    np.testing.assert_array_equal(image, episodes[1][1][1]["observation.image"])
    for key, value in episodes[1][1][1].items():  # the one-value columns too, as they were given
        if key != "observation.image":
            np.testing.assert_array_equal(
                np.asarray(loaded[4][key]).reshape(np.shape(value)), value, err_msg=key
            )


def test_write_round_refuses_bad_frames_empty_episodes_and_used_datasets(tmp_path):
    experiment = ExperimentDir(tmp_path)
    good = _episodes(np.random.default_rng(3), [3])
    with pytest.raises(ValueError, match="has no frame"):
        experiment.write_round(0, _features(), TASKS, [*good, ("task a", [])])
    bad = [("task a", [{**good[0][1][0], "action": np.zeros(3, dtype=np.float32)}])]
    with pytest.raises(ValueError, match="action"):
        experiment.write_round(0, _features(), TASKS, bad)
    dataset = experiment.write_round(0, _features(), TASKS, good)
    from lerobot_mtdagger.datasets.round_writer import write_round_episodes

    with pytest.raises(ValueError, match="empty, freshly created"):
        write_round_episodes(dataset, good)


def test_unsaved_frames_counts_lerobots_buffer_after_an_episode_is_saved(tmp_path):
    """LeRobot 0.4's ``dataset.writer`` becomes a ParquetWriter once an episode is saved."""
    from lerobot_mtdagger.utils.lerobot_compat import unsaved_frames

    experiment = ExperimentDir(tmp_path)
    dataset = experiment.create_round(0, _features(), TASKS)
    (task, frames), second = _episodes(np.random.default_rng(6), [3, 2])
    with quiet_third_party():
        for frame in frames:
            dataset.add_frame({**frame, "task": task})
        save_episode_with_success(dataset, frames)
        assert unsaved_frames(dataset) == 0
        dataset.add_frame({**second[1][0], "task": second[0]})
    assert unsaved_frames(dataset) == 1


def test_fast_episode_stats_equal_lerobots_bit_for_bit():
    from lerobot.datasets.compute_stats import compute_episode_stats

    from lerobot_mtdagger.utils.lerobot_compat import DEFAULT_FEATURES

    rng = np.random.default_rng(4)
    features = {
        "vector": {"dtype": "float32", "shape": (7,), "names": None},
        "cloud": {"dtype": "float32", "shape": (5, 3), "names": None},
        "flag": {"dtype": "bool", "shape": (1,), "names": None},
        "count": {"dtype": "int64", "shape": (1,), "names": None},
        "wide": {"dtype": "float64", "shape": (2,), "names": None},
        **DEFAULT_FEATURES,
    }
    for length in (2, 3, 17, 400):
        vector = rng.standard_normal((length, 7)).astype(np.float32)
        vector[:, 0] = 1.25  # constant column
        vector[:, 1] = np.round(vector[:, 1])  # many ties on bin edges
        buffer = {
            "vector": vector,
            "cloud": rng.standard_normal((length, 5, 3)).astype(np.float32),
            "flag": rng.random((length, 1)) < 0.3,
            "count": rng.integers(-5, 1_000_000, (length, 1)),
            "wide": rng.standard_normal((length, 2)) * 1e6,
            "timestamp": np.arange(length) / 80,
            "frame_index": np.arange(length),
            "episode_index": np.full((length,), 3),
            "index": np.arange(100, 100 + length),
            "task_index": np.full((length,), 1),
        }
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # ours must not warn
            ours = _vector_episode_stats(buffer, features)
        with quiet_third_party():
            theirs = compute_episode_stats(buffer, features)
        assert list(ours) == list(theirs)
        for key in theirs:
            assert list(ours[key]) == list(theirs[key]), key
            for name, value in theirs[key].items():
                assert ours[key][name].dtype == value.dtype, (key, name)
                np.testing.assert_array_equal(ours[key][name], value, err_msg=f"{key} {name}", strict=True)
