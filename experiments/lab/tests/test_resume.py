"""``experiments/resume.sh``: a step that would pass the session's end is put off until the steps that
fit have run; a one-run script gets its arguments, from the study's frozen worktree, and runs once
whatever the core."""

from __future__ import annotations

import os
import subprocess
from datetime import datetime, timedelta, timezone
from pathlib import Path

import pytest

RESUME = Path(__file__).resolve().parents[2] / "resume.sh"


def bash(script: str, cwd: Path, **env: str) -> subprocess.CompletedProcess:
    """``script`` run by bash in ``cwd`` with resume.sh's functions sourced."""
    return subprocess.run(
        ["bash", "-c", f"source {RESUME}\n{script}"],
        cwd=cwd,
        env={"PATH": "/usr/bin:/bin", "HOME": str(cwd), **env},
        capture_output=True,
        text=True,
    )


def in_minutes(minutes: int, now: datetime | None = None) -> str:
    """The time of day (UTC, ``HH:MM``) ``minutes`` from ``now`` (default: this moment)."""
    return ((now or datetime.now(timezone.utc)) + timedelta(minutes=minutes)).strftime("%H:%M")


@pytest.mark.parametrize(("end_in", "step", "starts"), [(90, 60, True), (50, 60, False)])
def test_a_step_starts_only_if_it_ends_before_session_end(tmp_path, end_in, step, starts):
    result = bash(f"fits {step}", tmp_path, SESSION_END=in_minutes(end_in))
    assert (result.returncode == 0) is starts
    assert ("would pass SESSION_END" in result.stdout) is not starts


@pytest.mark.parametrize(("end_in", "step", "starts"), [(90, 60, True), (50, 60, False)])
def test_a_session_end_past_midnight_is_tomorrows(tmp_path, end_in, step, starts):
    """At 23:30 UTC, a SESSION_END of 01:00 is 90 minutes away, not 22.5 hours ago."""
    fake_now = "23:30"
    date_at = tmp_path / "bin" / "date"  # `date` as at 23:30 today, for `now`; others answered by date
    date_at.parent.mkdir()
    now_line = f'[ "$*" = "-u +%s" ] && exec /usr/bin/date -u -d {fake_now} +%s'
    date_at.write_text(f'#!/bin/bash\n{now_line}\nexec /usr/bin/date "$@"\n')
    date_at.chmod(0o755)
    end = in_minutes(end_in, datetime.now(timezone.utc).replace(hour=23, minute=30))
    result = bash(f"fits {step}", tmp_path, SESSION_END=end, PATH=f"{date_at.parent}:/usr/bin:/bin")
    assert (result.returncode == 0) is starts, result.stdout + result.stderr


def test_without_session_end_every_step_starts(tmp_path):
    assert bash("fits 100000", tmp_path).returncode == 0


@pytest.fixture
def checkout(tmp_path):
    """A stand-in ../main with one commit, and a one-run script that logs where and how it ran."""
    main = tmp_path / "main"
    main.mkdir()
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-C", str(main)]
    subprocess.run(["git", "init", "-q", str(main)], check=True)
    (main / "file").write_text("frozen\n")
    subprocess.run([*git, "add", "file"], check=True)
    subprocess.run([*git, "commit", "-q", "-m", "c"], check=True)
    commit = subprocess.run([*git, "rev-parse", "HEAD"], capture_output=True, text=True).stdout.strip()
    (main / ".venv").mkdir()
    (main / "outputs").mkdir()
    script = tmp_path / "one_run.sh"
    script.write_text('echo "$PWD $* $(cat file)" >> outputs/calls\nsleep "${NAP:-0}"\n')
    return main, commit, script


def test_a_one_run_script_gets_its_arguments_in_the_frozen_worktree(checkout):
    main, commit, script = checkout
    result = bash(f"study dev study-code-dev {commit} 0 {script} fixed 100", main)
    assert result.returncode == 0, result.stdout + result.stderr
    assert (main / "outputs" / "calls").read_text().split() == [
        str(main.parent / "study-code-dev"),
        "fixed",
        "100",
        "frozen",
    ]
    assert (main.parent / "study-code-dev" / "outputs").resolve() == main / "outputs"


def test_a_worktree_frozen_at_another_commit_is_refused(checkout):
    """A study's code changes only under a new worktree name: an old one is never run as a new commit."""
    main, commit, script = checkout
    assert bash(f"worktree study-code-dev {commit}", main).returncode == 0
    git = ["git", "-c", "user.name=t", "-c", "user.email=t@t", "-C", str(main)]
    (main / "file").write_text("changed\n")
    subprocess.run([*git, "commit", "-q", "-am", "d"], check=True)
    result = bash(f"study dev study-code-dev HEAD 0 {script} fixed 100", main)
    assert result.returncode == 1 and f"../study-code-dev is at {commit[:7]}, not HEAD" in result.stdout
    assert not (main / "outputs" / "calls").exists()


@pytest.mark.parametrize("second_core", [0, 1])
def test_the_same_run_twice_is_refused_on_either_core(checkout, second_core):
    main, commit, script = checkout
    first = f"study dev study-code-dev {commit} 0 {script} fixed 100"
    second = f"study dev study-code-dev {commit} {second_core} {script} fixed 100"
    result = bash(f"NAP=3 {first} & sleep 1; {second}; echo second=$?; wait", main)
    assert "already running" in result.stdout and "second=1" in result.stdout
    assert len((main / "outputs" / "calls").read_text().splitlines()) == 1


def test_a_run_that_would_pass_session_end_starts_after_those_that_fit(checkout):
    main, commit, script = checkout
    chain = f"ONE_RUN={script}\ndev_run 0 epochs 101 250; dev_run 0 fixed 100 30; run_put_off"
    result = bash(chain, main, SESSION_END=in_minutes(60), PIXELS_COMMIT=commit)
    assert result.returncode == 0, result.stdout + result.stderr
    calls = (main / "outputs" / "calls").read_text().splitlines()
    assert [call.split()[1:3] for call in calls] == [["fixed", "100"], ["epochs", "101"]]
    assert "put off: about 250 min would pass SESSION_END" in result.stdout
    assert "starting the step put off: dev_start 0 epochs 101" in result.stdout


def test_both_cores_may_ask_for_the_same_new_worktree_at_once(checkout):
    main, commit, script = checkout
    steps = [
        f"study dev study-code-dev {commit} {core} {script} fixed {seed}"
        for core, seed in ((0, 100), (1, 102))
    ]
    result = bash(f"{steps[0]} & {steps[1]} & wait", main)
    assert "cannot make" not in result.stdout, result.stdout + result.stderr
    calls = sorted((main / "outputs" / "calls").read_text().splitlines())
    assert [call.split()[2] for call in calls] == ["100", "102"]


def development_study(tmp_path: Path, missing: tuple[str, int]) -> tuple[Path, Path]:
    """A stand-in ../main whose development study holds every run's phase 5 but ``missing``'s, and a
    report.sh that notes it ran; ../main and the record ``missing``'s run would write."""
    main = tmp_path / "main"
    study = main / "experiments" / "pixels-dagger-epochs-dev"
    study.mkdir(parents=True)
    (main / "outputs").mkdir()
    (study / "report.sh").write_text("touch outputs/reported\n")
    for arm in ("epochs", "fixed"):
        for seed in (100, 101, 102):
            last = study / "records" / arm / f"uniform-seed{seed}" / "policies" / "round-005"
            if (arm, seed) != missing:
                last.mkdir(parents=True)
                (last / "training.json").write_text('{"round": 5, "eval": {}}')
    return main, study / "records" / missing[0] / f"uniform-seed{missing[1]}" / "policies" / "round-005"


def test_the_development_report_waits_for_all_six_runs(tmp_path):
    main, last = development_study(tmp_path, ("fixed", 102))
    result = bash("dev_report", main)
    assert result.returncode == 1 and "fixed seed 102 not in its records yet" in result.stdout
    assert not (main / "outputs" / "reported").exists()
    last.mkdir(parents=True)
    (last / "training.json").write_text('{"round": 5, "eval": {}}')
    assert bash("dev_report", main).returncode == 0
    assert (main / "outputs" / "reported").exists()


def test_the_queue_puts_off_what_does_not_fit_then_runs_matched_runs_on_both_cores(checkout, tmp_path):
    main, commit, script = checkout
    script.write_text('echo "$(grep Cpus_allowed_list /proc/self/status | cut -f2) $*" >> outputs/calls\n')
    result = subprocess.run(
        ["bash", str(RESUME)],
        cwd=main,
        env={
            "PATH": "/usr/bin:/bin",
            "HOME": str(main),
            "SESSION_END": in_minutes(60),
            "FIXED_MIN": "30",
            "EPOCHS_MIN": "500",
            "BOTH_MIN": "500",
            "PIXELS_COMMIT": commit,
            "PIXELS_EVAL_COMMIT": commit,
            "ONE_RUN": str(script),
            "MATCHED_RUN": str(script),
            "DEV": str(tmp_path / "no-records-yet"),
        },
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    calls = (main / "outputs" / "calls").read_text().splitlines()
    by_core = {c: [call.split(maxsplit=1)[1] for call in calls if call.split()[0] == c] for c in "01"}
    assert by_core["0"] == ["fixed 100", "fixed 101", "epochs 101"]
    assert by_core["1"] == ["fixed 102", "epochs 102"]
    matched = [call.split(maxsplit=1)[1] for call in calls if call.split()[0] == "0-1"]
    assert matched == [
        "uniform 0",
        "uniform 1",
        "need 0",
        "need 1",
        "gain 0",
        "gain 1",
        "uniform 2",
        "need 2",
        "gain 2",
    ]  # one at a time, after the development steps of both cores
    assert calls[-len(matched) :] == [f"0-1 {run}" for run in matched]
    assert result.stdout.count("put off: about 500 min") == 11  # the 2 epochs runs and the 9 matched runs
    assert result.stdout.count("not in its records yet") == 4  # each core's report: when due, and again


def test_the_development_report_waits_for_a_run_another_chain_is_running(tmp_path):
    main, last = development_study(tmp_path, ("epochs", 102))
    (tmp_path / "record.json").write_text('{"round": 5, "eval": {}}')
    started = (
        tmp_path / "started"
    )  # the stand-in run holds the lock (a loaded machine may be slow to start it)
    running = (
        f"touch {started} && mkdir -p {last} && sleep 2 && cp {tmp_path / 'record.json'} {last}/training.json"
    )
    chain = (
        f"flock outputs/.pixels-dagger-epochs-dev-epochs-102.lock bash -c '{running}' & "
        f"until [ -f {started} ]; do sleep 0.1; done; dev_report"
    )
    result = bash(chain, main)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "waiting for epochs seed 102, which another chain is running" in result.stdout
    assert (main / "outputs" / "reported").exists()


@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="needs two cores to pin a run to both")
def test_every_matched_run_gets_both_cores_and_two_threads(checkout):
    main, commit, script = checkout
    script.write_text(
        'echo "$(grep Cpus_allowed_list /proc/self/status | cut -f2) $OMP_NUM_THREADS $*" >> outputs/calls\n'
    )
    result = bash(f"MATCHED_RUN={script} PIXELS_EVAL_COMMIT={commit}\nmatched_start need 0", main)
    assert result.returncode == 0, result.stdout + result.stderr
    assert (main / "outputs" / "calls").read_text().split() == ["0-1", "2", "need", "0"]
