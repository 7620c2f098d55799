"""Helpers shared by tests that tamper with committed experiments or kill runs."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any


def edit_round_record(round_root: Path, edit: Callable[[dict[str, Any]], None]) -> None:
    """Applies ``edit`` to a committed round's record in ``meta/mtdagger.json`` and its info.json mirror.

    The mirror is edited where the round has one (rounds written on LeRobot 0.4).
    """
    sidecar = round_root / "meta" / "mtdagger.json"
    record = json.loads(sidecar.read_text())
    edit(record)
    sidecar.write_text(json.dumps(record))
    info_path = round_root / "meta" / "info.json"
    info = json.loads(info_path.read_text())
    if "mtdagger" in info:
        info["mtdagger"] = record
        info_path.write_text(json.dumps(info))
    # the state the test makes is one a run could have committed: its ledger is made anew to match
    experiment_root = round_root.parent.parent
    if (experiment_root / "ledger.json").is_file():
        from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir

        (experiment_root / "ledger.json").unlink()
        ExperimentDir(experiment_root).update_ledger()


def edit_info_mirror(info: dict[str, Any], edit: Callable[[dict[str, Any]], None]) -> None:
    """Applies ``edit`` to a round's ``info.json`` values' record mirror, where it has one (LeRobot 0.4)."""
    if "mtdagger" in info:
        edit(info["mtdagger"])


def child_pids(pid: int) -> list[int]:
    """Process ids whose parent is ``pid`` (Linux /proc)."""
    children = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            children.append(int(stat.parent.name))
    return children


def is_running(pid: int) -> bool:
    """Whether process ``pid`` exists and is not a zombie waiting to be reaped."""
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


def kill_9_and_check_workers_end(process: subprocess.Popen, workers: int | None = None) -> None:
    """SIGKILLs a run and checks that its env worker processes end within 20 s.

    ``workers``: how many env worker processes the run must have had when killed (None: any).
    """
    children = child_pids(process.pid)
    if workers is not None:
        assert len(children) == workers, f"the run should have its {workers} env workers"
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    deadline = time.time() + 20
    while any(is_running(pid) for pid in children) and time.time() < deadline:
        time.sleep(0.05)
    assert not any(is_running(pid) for pid in children), "env workers outlived the run"


def small_drawer_cloud_args(output_dir: Path) -> list[str]:
    """``run`` options of a two-drawer point-cloud run (one DAgger round, 128 points) in seconds."""
    return [
        "--preset=drawers-pointcloud",
        "--suite.tasks=[drawer-bar-wide,drawer-lip-shallow]",
        "--dagger.rounds=1",
        "--dagger.initial_demos=1",
        "--dagger.budget_per_task=1",
        "--scheduler.n_min=1",
        "--training.steps_per_round=20",
        "--rollout.eval_episodes=1",
        "--suite.num_points=128",
        "--rollout.max_steps=80",
        "--progress=false",
        f"--output_dir={output_dir}",
    ]


TINY_ROUND = [
    "--dagger.rounds=1",
    "--dagger.initial_demos=1",
    "--dagger.budget_per_task=1",
    "--training.steps_per_round=5",
    "--rollout.eval_episodes=1",
    "--rollout.max_steps=20",
    "--rollout.workers=0",
    "--policy.batch_size=8",
    "--policy.state_hidden_dims=[16]",
    "--policy.head_hidden_dims=[16]",
    "--progress=false",
]
"""One DAgger round of a tiny ``mtdagger`` policy, in-process envs (add the suite and ``--output_dir``)."""


TOY_COMPARE = [
    "--suite.name=toy",
    "--dagger.rounds=2",
    "--dagger.initial_demos=1",
    "--dagger.budget_per_task=2",
    "--training.steps_per_round=20",
    "--rollout.eval_episodes=2",
    "--policy.batch_size=32",
    "--policy.state_hidden_dims=[32]",
    "--policy.head_hidden_dims=[32]",
]
"""Run options of a small ``compare`` on the toy suite: two DAgger rounds of a tiny ``mtdagger`` policy."""
