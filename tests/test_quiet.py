"""The quiet console (``utils.quiet``): ``quiet_third_party`` must silence exactly the known third-party
noise and put everything back (the round writer's tests: ``test_round_writer.py``).
"""

from __future__ import annotations

import importlib
import logging
import os
import re
import subprocess
import sys
import warnings

import numpy as np
import pytest

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.utils import quiet
from lerobot_mtdagger.utils.quiet import quiet_third_party
from tests.test_round_writer import TASKS, _episodes, _features, _record_stub

hf_tqdm = importlib.import_module("datasets.utils.tqdm")

BOOL_WARNING = r"Converting input from bool to <class 'numpy\.uint8'>"


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
