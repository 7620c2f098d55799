"""The quiet console (``utils.quiet``) and the one-go round writer (``ExperimentDir.write_round``).

``quiet_third_party`` must silence exactly the known third-party noise and put everything back; the
round writer must produce what LeRobot's own ``add_frame`` / ``save_episode`` loop produces.
"""

from __future__ import annotations

import importlib
import json
import logging
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import numpy as np
import pyarrow.parquet as pq
import pytest

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, round_name
from lerobot_mtdagger.datasets.records import StepOutcome, dagger_columns, round_features
from lerobot_mtdagger.datasets.round_writer import _vector_episode_stats, save_episode_with_success
from lerobot_mtdagger.utils import quiet
from lerobot_mtdagger.utils.quiet import quiet_third_party

hf_tqdm = importlib.import_module("datasets.utils.tqdm")

BOOL_WARNING = r"Converting input from bool to <class 'numpy\.uint8'>"


class _Records(logging.Handler):
    """Collects the formatted messages it handles."""

    def __init__(self) -> None:
        super().__init__(level=logging.DEBUG)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(f"{record.name}: {record.getMessage()}")


@pytest.fixture
def root_records():
    """A handler on the root logger at INFO for the test; root's level and handlers are restored."""
    root = logging.getLogger()
    handler, level = _Records(), root.level
    root.addHandler(handler)
    root.setLevel(logging.INFO)
    yield handler
    root.removeHandler(handler)
    root.setLevel(level)


def _logging_state() -> dict:
    root = logging.getLogger()
    names = ["root", *quiet.QUIETED_LOGGERS, "lerobot", "datasets"]
    return {
        "root_filters": list(root.filters),
        "root_handlers": list(root.handlers),
        "handler_filters": [list(h.filters) for h in root.handlers],
        "levels": {name: logging.getLogger(None if name == "root" else name).level for name in names},
        "disabled": logging.root.manager.disable,
    }


def _state() -> dict:
    return {
        "logging": _logging_state(),
        "bars_disabled": hf_tqdm.are_progress_bars_disabled(),
        "warning_filters": list(warnings.filters),
        "stdout": sys.stdout,
    }


# -------------------------------------------------------------------------------------------------
# quiet_third_party: what it silences
# -------------------------------------------------------------------------------------------------


def _log_lerobots_codec_line() -> str:
    """Makes LeRobot log its "Using video codec" line with its own code; returns the logger's name.

    LeRobot 0.4 logs it on the root logger (``video_utils.resolve_vcodec``), LeRobot 0.6 on the named
    logger of ``lerobot.configs.video`` (``VideoEncoderConfig`` resolves its codec when made).
    """
    try:
        from lerobot.datasets.video_utils import resolve_vcodec  # LeRobot 0.4
    except ImportError:
        from lerobot.configs.video import VideoEncoderConfig  # LeRobot >= 0.6

        VideoEncoderConfig(vcodec="libsvtav1")
        return "lerobot.configs.video"
    resolve_vcodec("libsvtav1")
    return "root"


def test_the_video_codec_line_is_dropped_and_nothing_else(root_records):
    with quiet_third_party():
        _log_lerobots_codec_line()
        logging.info("Using video codec: from somewhere else")  # root logger, another module
        logging.getLogger("lerobot_mtdagger.test").info("Using video codec: ours")
        logging.info("another root message")
    assert root_records.messages == [
        "root: Using video codec: from somewhere else",
        "lerobot_mtdagger.test: Using video codec: ours",
        "root: another root message",
    ]
    logger_name = _log_lerobots_codec_line()
    assert root_records.messages[-1] == f"{logger_name}: Using video codec: libsvtav1", "back after the block"


def test_lerobot_06s_named_loggers_are_filtered_inside_only(root_records):
    # LeRobot 0.6 logs the codec and merge steps through named loggers: both lines' loggers are covered
    for name, prefixes in quiet.NAMED_MESSAGES.items():
        with quiet_third_party():
            logging.getLogger(name).info(prefixes[0] + "x")
            logging.getLogger(name).info("something else")
        logging.getLogger(name).info(prefixes[0] + "y")
    expected = []
    for name, prefixes in quiet.NAMED_MESSAGES.items():
        expected += [f"{name}: something else", f"{name}: {prefixes[0]}y"]
    assert root_records.messages == expected


def test_lerobot_dataset_create_and_load_log_no_codec_line(tmp_path, root_records):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    experiment = ExperimentDir(tmp_path)
    episodes = _episodes(np.random.default_rng(0), [3, 4])
    dataset = experiment.write_round(0, _features(), TASKS, episodes)
    experiment.commit_round(0, dataset, _record_stub())
    with quiet_third_party():
        LeRobotDataset("local/round-000", root=experiment.round_root(0))
    assert not [m for m in root_records.messages if "video codec" in m]


def _lerobot_warns_on_bool_stats() -> bool:
    """Whether this LeRobot's ``compute_episode_stats`` warns on a bool column (0.4 does; 0.6 casts to
    float32 first and does not)."""
    from lerobot.datasets.compute_stats import compute_episode_stats

    data = {"flag": np.array([[True], [False], [True]])}
    features = {"flag": {"dtype": "bool", "shape": (1,), "names": None}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        compute_episode_stats(data, features)
    return any(re.search(BOOL_WARNING, str(item.message)) for item in caught)


def test_the_bool_histogram_warning_is_ignored_only_from_lerobots_stats():
    from lerobot.datasets.compute_stats import compute_episode_stats

    warns = _lerobot_warns_on_bool_stats()
    data = {"flag": np.array([[True], [False], [True]])}
    features = {"flag": {"dtype": "bool", "shape": (1,), "names": None}}
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        with quiet_third_party():
            compute_episode_stats(data, features)
            assert not caught, "LeRobot's stats on a bool column are silenced"
            np.histogram(np.array([True, False]), bins=np.linspace(0, 1, 3))  # not from LeRobot
        assert len(caught) == 1 and re.search(BOOL_WARNING, str(caught[0].message))
        compute_episode_stats(data, features)
    assert len(caught) == 1 + int(warns), "the same call warns again after the block (where LeRobot warns)"


def test_datasets_progress_bars_are_off_inside_and_restored(capfd):
    import datasets

    for disabled_before in (False, True):
        if disabled_before:
            hf_tqdm.disable_progress_bars()
        else:
            hf_tqdm.enable_progress_bars()
        try:
            with quiet_third_party():
                assert hf_tqdm.are_progress_bars_disabled()
                datasets.Dataset.from_dict({"x": [1, 2, 3]}).map(lambda row: row)
            assert hf_tqdm.are_progress_bars_disabled() is disabled_before
        finally:
            hf_tqdm.enable_progress_bars()
    assert "Map" not in capfd.readouterr().err


def test_lerobots_suppress_progress_bars_inside_the_block_does_not_leak_out():
    from lerobot.utils.utils import SuppressProgressBars

    hf_tqdm.disable_progress_bars()
    try:
        with quiet_third_party(), SuppressProgressBars():  # re-enables the bars unconditionally on exit
            pass
        assert hf_tqdm.are_progress_bars_disabled(), "the state before the block is put back"
    finally:
        hf_tqdm.enable_progress_bars()


def test_the_pretrained_weights_line_is_dropped_from_stdout_and_nothing_else(capsys):
    with quiet_third_party():
        print("Loading weights from local directory")
        print("Loading weights from local directory, and more")
        print("kept")
        sys.stdout.write("Loading weights from local directory\n")
        print("tail", end="")
    print()
    assert capsys.readouterr().out == "Loading weights from local directory, and more\nkept\ntail\n"


def test_the_opengl_logger_is_raised_to_warning_inside_only(root_records):
    opengl = logging.getLogger("OpenGL.acceleratesupport")
    level = opengl.level
    try:
        opengl.setLevel(logging.NOTSET)
        with quiet_third_party():
            assert opengl.level == logging.WARNING
        assert opengl.level == logging.NOTSET
        opengl.setLevel(logging.ERROR)  # already quieter: left alone
        with quiet_third_party():
            assert opengl.level == logging.ERROR
    finally:
        opengl.setLevel(level)


# -------------------------------------------------------------------------------------------------
# quiet_third_party: everything is restored
# -------------------------------------------------------------------------------------------------


def test_everything_is_restored_on_exit_and_on_error():
    before = _state()
    with quiet_third_party():
        inside = _state()
    assert _state() == before
    assert inside["logging"]["root_filters"] != before["logging"]["root_filters"]
    assert inside["warning_filters"] != before["warning_filters"]
    assert inside["stdout"] is not before["stdout"]
    with pytest.raises(RuntimeError, match="boom"), quiet_third_party():
        raise RuntimeError("boom")
    assert _state() == before


class _ImportTimeWarning(UserWarning):
    pass


def test_warning_filters_added_inside_by_others_are_kept():
    with warnings.catch_warnings():  # restores this test's changes at the end
        before = list(warnings.filters)
        with quiet_third_party():
            warnings.filterwarnings("ignore", message="an import-time filter", category=UserWarning)
            warnings.simplefilter("error", _ImportTimeWarning)
        added = [item for item in warnings.filters if item not in before]
        expected = [("error", _ImportTimeWarning), ("ignore", UserWarning)]
        assert [(item[0], item[2]) for item in added] == expected
        assert added[1][1].pattern == "an import-time filter"
        assert len(warnings.filters) == len(before) + 2, "our own filter is gone"


def test_nested_blocks_restore_in_order():
    before = _state()
    with quiet_third_party():
        outer = _state()
        with quiet_third_party():
            pass
        assert _state()["logging"] == outer["logging"]
        assert _state()["bars_disabled"] and _state()["stdout"] is outer["stdout"]
    assert _state() == before


def test_the_users_logging_configuration_is_not_touched(root_records):
    root = logging.getLogger()
    handler_filters = [list(h.filters) for h in root.handlers]
    with quiet_third_party():
        assert [list(h.filters) for h in root.handlers] == handler_filters, "handlers untouched"
        assert root.level == logging.INFO
        logging.getLogger("lerobot_mtdagger.anything").info("still logged")
    assert root_records.messages == ["lerobot_mtdagger.anything: still logged"]


# -------------------------------------------------------------------------------------------------
# write_round: the same dataset as LeRobot's add_frame / save_episode loop, much cheaper
# -------------------------------------------------------------------------------------------------

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


# -------------------------------------------------------------------------------------------------
# The console of a real (toy) run
# -------------------------------------------------------------------------------------------------


SUMMARY = re.compile(r"^round \d+: demos/task ")


def test_a_toy_run_without_progress_prints_only_its_summary_lines(tmp_path):
    env = {**os.environ, "MUJOCO_GL": "egl"}
    env.pop("HF_DATASETS_DISABLE_PROGRESS_BARS", None)
    command = [
        sys.executable,
        "-m",
        "lerobot_mtdagger.cli",
        "run",
        "--suite.name=toy",
        f"--output_dir={tmp_path / 'run'}",
        "--training.steps_per_round=20",
        "--dagger.rounds=2",
        "--progress=false",
    ]
    result = subprocess.run(command, capture_output=True, text=True, env=env, timeout=600, check=True)
    out = [line for line in result.stdout.splitlines() if line.strip()]
    err = [line for line in result.stderr.splitlines() if line.strip()]
    summaries = [line for line in out if SUMMARY.match(line)]
    assert len(summaries) == 3, result.stdout
    assert all(SUMMARY.match(line) or line.startswith("experiment ") for line in out), result.stdout
    assert err == [], result.stderr  # summaries go to stdout and run.log, once each
    log = (tmp_path / "run" / "run.log").read_text()
    assert len(re.findall(r"round \d+: demos/task ", log)) == 3
