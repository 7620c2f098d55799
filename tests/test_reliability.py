"""Reliability of experiment folders: one writer at a time, policy folders that cannot run code."""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
import sys

import pytest

from lerobot_mtdagger.checkpoints import UntrustedCheckpointError
from lerobot_mtdagger.dagger import run
from lerobot_mtdagger.evaluate import PolicyRunner
from lerobot_mtdagger.rounds import LOCK_FILE, ExperimentDir, ExperimentLockedError
from tests.test_toy import toy_config


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    root = tmp_path_factory.mktemp("lock") / "toy"
    run(toy_config(root, "--rounds=1"))
    return root


def test_a_second_writer_is_refused_at_once_naming_the_folder_and_the_process(finished):
    before = sorted(p.relative_to(finished) for p in finished.rglob("*"))
    expected = rf"{finished} is being written by .*pid {os.getpid()}"
    with ExperimentDir(finished).writer_lock(), pytest.raises(ExperimentLockedError, match=expected):
        run(toy_config(finished, "--rounds=1", "--resume=true"))
    assert sorted(p.relative_to(finished) for p in finished.rglob("*")) == before
    assert run(toy_config(finished, "--rounds=1", "--resume=true")), "the lock is released on exit"


def test_a_killed_writer_leaves_no_stale_lock(finished):
    code = (
        "import sys, time\n"
        "from lerobot_mtdagger.rounds import ExperimentDir\n"
        f"with ExperimentDir({str(finished)!r}).writer_lock():\n"
        "    print('locked', flush=True)\n"
        "    time.sleep(60)\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        assert (finished / LOCK_FILE).read_text() == str(holder.pid)
        second_writer = ExperimentDir(finished).writer_lock()
        with pytest.raises(ExperimentLockedError, match=f"pid {holder.pid}"), second_writer:
            pass
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    with ExperimentDir(finished).writer_lock():
        assert (finished / LOCK_FILE).read_text() == str(os.getpid())


def hostile_copy(finished, tmp_path, step):
    folder = tmp_path / "policy"
    shutil.copytree(ExperimentDir(finished).policy_root(1), folder)
    path = folder / "policy_preprocessor.json"
    config = json.loads(path.read_text())
    config["steps"].insert(0, step)
    path.write_text(json.dumps(config))
    return folder


def test_a_policy_folder_naming_a_class_is_refused_before_anything_runs(finished, tmp_path):
    marker = tmp_path / "ran"
    step = {"class": "os.system", "config": {"command": f"touch {marker}"}}
    folder = hostile_copy(finished, tmp_path, step)
    expected = r"Step 0 of .*policy_preprocessor.json names the Python class 'os.system'.*--trust_checkpoint"
    with pytest.raises(UntrustedCheckpointError, match=expected):
        PolicyRunner.from_pretrained(folder)
    assert not marker.exists()


def test_a_policy_folder_naming_an_unregistered_step_is_refused(finished, tmp_path):
    folder = hostile_copy(finished, tmp_path, {"registry_name": "made_up_step", "config": {}})
    with pytest.raises(UntrustedCheckpointError, match="'made_up_step', which is not a registered"):
        PolicyRunner.from_pretrained(folder)


def test_the_runs_own_policies_load_without_trust(finished):
    runner = PolicyRunner.from_pretrained(ExperimentDir(finished).policy_root(1))
    assert runner.policy.config.task_names
