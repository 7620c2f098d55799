"""``experiments/pixels-eval/run-missing.sh``: a restart runs exactly the runs no record holds finished.

The script is run with ``CLI=echo`` (it prints its ``compare`` calls); each call is planned with
``compare``'s own ``jobs_for`` to check that it names the missing run and nothing else.
"""

from __future__ import annotations

import shlex
import subprocess
from pathlib import Path

import pytest

from lerobot_mtdagger.analysis.compare import CompareConfig, jobs_for, split_arguments
from lerobot_mtdagger.utils.parsing import parse_options

SCRIPT = Path(__file__).resolve().parents[2] / "pixels-eval" / "run-missing.sh"
DECISION = "Decision: BC samples balanced (highest mean over budgets)\n"
BC_RUNS = [f"bc-{budget}demos-seed{seed}" for seed in (0, 1, 2) for budget in range(10, 70, 10)]
DAGGER_RUNS = [f"{method}-seed{seed}" for seed in (0, 1, 2) for method in ("uniform", "need", "gain")]


def hold(folder: Path, name: str, last_phase: int) -> None:
    """Writes the training record of phases 0..last_phase of run ``name`` under ``folder``."""
    for phase in range(last_phase + 1):
        record = folder / name / "policies" / f"round-{phase:03d}" / "training.json"
        record.parent.mkdir(parents=True, exist_ok=True)
        record.write_text("{}")


@pytest.fixture
def worktree(tmp_path):
    """A stand-in for the frozen worktree: the BC decision, records/ and outputs/ folders."""
    decision = tmp_path / "docs" / "results" / "pixels-bc-dev" / "table.txt"
    decision.parent.mkdir(parents=True)
    decision.write_text(DECISION)
    return tmp_path


def planned_runs(worktree: Path, records: Path) -> list[str]:
    """The run names of every ``compare`` call the script makes, each planned by ``jobs_for``."""
    result = subprocess.run(
        ["bash", str(SCRIPT)],
        cwd=worktree,
        env={"CLI": "echo", "RECORDS": str(records), "JOBS": "1", "PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
    )
    assert result.returncode == 0, result.stderr
    names = []
    for line in result.stdout.splitlines():
        command, *arguments = shlex.split(line)
        assert command == "compare"
        own, run_args = split_arguments(arguments)
        assert run_args == [
            "--preset=metaworld-pixels",
            "--rollout.eval_episodes=20",
            "--progress=false",
            "--training.sampling=balanced",
        ]
        config = parse_options(CompareConfig, own, "lerobot-mtdagger compare")
        assert config.jobs == 1 and config.output_dir == Path("outputs/pixels-eval")
        names += [job.name for job in jobs_for(config, run_args, num_tasks=10)]
    return names


def test_a_restart_without_outputs_runs_only_the_runs_records_lack(worktree):
    records = worktree / "records"
    for name in BC_RUNS:
        if name != "bc-30demos-seed1":
            hold(records, name, 0)
    for name in DAGGER_RUNS:
        if name not in ("need-seed2", "gain-seed2"):
            hold(records, name, 5)
    hold(records, "need-seed2", 4)  # cut in its last phase: its records end at phase 4
    assert planned_runs(worktree, records) == ["bc-30demos-seed1", "need-seed2", "gain-seed2"]


def test_runs_finished_in_outputs_but_not_yet_saved_are_not_run_again(worktree):
    records = worktree / "records"
    for name in BC_RUNS:
        hold(records, name, 0)
    outputs = worktree / "outputs" / "pixels-eval" / "runs"
    for name in DAGGER_RUNS[:-1]:
        hold(outputs, name, 5)
    assert planned_runs(worktree, records) == ["gain-seed2"]


def test_nothing_held_runs_run_sh_s_whole_plan_in_its_order(worktree):
    run_sh = CompareConfig(methods=["bc", "uniform", "need", "gain"], seeds=[0, 1, 2])
    run_args = ["--preset=metaworld-pixels", "--rollout.eval_episodes=20", "--training.sampling=balanced"]
    expected = [job.name for job in jobs_for(run_sh, run_args, num_tasks=10)]
    assert len(expected) == 27
    assert planned_runs(worktree, worktree / "records") == expected


def test_without_the_bc_decision_it_stops_and_says_where_to_copy_it_from(worktree):
    (worktree / "docs" / "results" / "pixels-bc-dev" / "table.txt").unlink()
    result = subprocess.run(
        ["bash", str(SCRIPT)],
        cwd=worktree,
        env={"CLI": "echo", "PATH": "/usr/bin:/bin"},
        capture_output=True,
        text=True,
    )
    assert result.returncode == 1
    assert "copy it from ../main" in result.stderr
    assert result.stdout == ""
