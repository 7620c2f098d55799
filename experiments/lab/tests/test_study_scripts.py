"""``experiments/with_studies_paused.sh``: a command run with the studies' runs paused, always resumed."""

from __future__ import annotations

import re
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from lerobot_mtdagger.analysis.launchers import Job, job_command

SCRIPT = Path(__file__).resolve().parents[2] / "with_studies_paused.sh"
DEFAULT_PATTERN = re.search(r'STUDY_PATTERN:-"([^"]+)"', SCRIPT.read_text()).group(1)


def process_state(pid: int) -> str:
    """The one-letter state of a process (``T``: stopped)."""
    stat = Path(f"/proc/{pid}/stat").read_text()
    return stat.rsplit(")", 1)[1].split()[0]


@pytest.fixture
def fake_study(tmp_path):
    """A process whose command line names a unique marker, with one child (as a run's env worker)."""
    marker = f"fake-study-{uuid.uuid4().hex}"
    child = "import time; time.sleep(60)"
    code = (
        f"import subprocess, sys, time; subprocess.Popen([sys.executable, '-c', {child!r}]); time.sleep(60)"
    )
    parent = subprocess.Popen([sys.executable, "-c", code, marker])
    deadline = time.time() + 10
    children: list[str] = []
    while not children and time.time() < deadline:
        children = subprocess.run(
            ["pgrep", "-P", str(parent.pid)], capture_output=True, text=True
        ).stdout.split()
        time.sleep(0.05)
    assert children, "the fake study's child did not start"
    yield marker, [parent.pid, int(children[0])]
    for pid in (int(children[0]), parent.pid):
        subprocess.run(["kill", "-9", str(pid)], check=False)
    parent.wait()


def run_paused(marker: str, log: Path, *command: str) -> subprocess.CompletedProcess:
    environment = {"STUDY_PATTERN": marker, "STUDY_PAUSE_LOG": str(log), "PATH": "/usr/bin:/bin"}
    return subprocess.run(["bash", str(SCRIPT), *command], capture_output=True, text=True, env=environment)


def test_the_command_runs_while_the_study_and_its_workers_are_stopped_then_they_go_on(fake_study, tmp_path):
    marker, pids = fake_study
    states = " ".join(f"$(cut -d')' -f2 /proc/{pid}/stat | cut -d' ' -f2)" for pid in pids)
    result = run_paused(marker, tmp_path / "pauses.log", "bash", "-c", f"echo {states}")
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[0] == "T T"  # both stopped while the command ran
    assert "T" not in [process_state(pid) for pid in pids]  # and going on after
    window = (tmp_path / "pauses.log").read_text()
    assert re.fullmatch(
        r"paused 2 study process\(es\) \S+T\d\d:\d\d:\d\d-\d\d:\d\d:\d\d for: bash -c .*\n", window
    )


def test_a_failing_command_still_resumes_the_study_and_its_status_is_returned(fake_study, tmp_path):
    marker, pids = fake_study
    result = run_paused(marker, tmp_path / "pauses.log", "bash", "-c", "exit 3")
    assert result.returncode == 3
    assert "T" not in [process_state(pid) for pid in pids]


def test_no_command_is_refused_and_nothing_is_paused(fake_study, tmp_path):
    marker, pids = fake_study
    result = run_paused(marker, tmp_path / "pauses.log")
    assert result.returncode == 2 and "Give the command to run" in result.stderr
    assert "T" not in [process_state(pid) for pid in pids]


def test_the_default_pattern_matches_the_runs_compare_starts_and_not_compare_itself(tmp_path):
    command, _ = job_command(Job("need-seed0", ("--seed=0",), last_phase=2), tmp_path / "run", 1, 0)
    assert re.search(DEFAULT_PATTERN, " ".join(command))
    assert re.search(DEFAULT_PATTERN, ".venv/bin/lerobot-mtdagger run --preset=small")
    assert not re.search(DEFAULT_PATTERN, ".venv/bin/lerobot-mtdagger compare --methods=[need]")


def wait_stopped_function() -> str:
    """The text of the script's ``wait_stopped`` function."""
    function = re.search(r"^wait_stopped\(\) \{.*?^\}\n", SCRIPT.read_text(), re.DOTALL | re.MULTILINE)
    assert function is not None, "with_studies_paused.sh defines no wait_stopped() function"
    return function.group(0)


def wait_stopped_seconds(pids: list[int], stop_after: float | None) -> tuple[float, str]:
    """Runs the script's ``wait_stopped`` on ``pids``; returns its seconds and the first pid's state after
    (``gone`` if it has ended).

    Args:
        pids: The processes ``wait_stopped`` waits for (the script's ``PAUSED``).
        stop_after: Seconds after which a background ``kill -STOP`` stops them, or ``None`` for never.
    """
    paused = " ".join(str(pid) for pid in pids)
    stopper = f"(sleep {stop_after}; kill -STOP {paused}) &" if stop_after is not None else ""
    body = "\n".join(
        [
            wait_stopped_function(),
            f'PAUSED="{paused}"',
            stopper,
            "start=$EPOCHREALTIME; wait_stopped; end=$EPOCHREALTIME",
            # read here, as wait_stopped returns: once bash exits the stopper has run too
            f"state=$(cut -d')' -f2 /proc/{pids[0]}/stat 2> /dev/null | cut -d' ' -f2)",
            'echo "$start $end ${state:-gone}"',
        ]
    )
    result = subprocess.run(["bash", "-c", body], capture_output=True, text=True, check=True)
    start, end, state = result.stdout.split()
    return float(end) - float(start), state


def test_wait_stopped_returns_once_a_process_that_stops_late_is_stopped(fake_study):
    """A loaded machine may handle SIGSTOP a moment after ``kill`` returns: the command waits for it."""
    _, pids = fake_study
    seconds, state = wait_stopped_seconds(pids, stop_after=1.0)
    assert state == "T"
    assert 0.9 <= seconds < 4.0


def test_wait_stopped_gives_up_after_about_five_seconds_on_a_process_that_never_stops(fake_study):
    _, pids = fake_study
    seconds, state = wait_stopped_seconds(pids, stop_after=None)
    assert state != "T"
    assert 4.0 <= seconds < 12.0


def test_wait_stopped_returns_at_once_for_a_process_that_is_gone():
    gone = subprocess.Popen([sys.executable, "-c", "pass"])
    gone.wait()
    seconds, state = wait_stopped_seconds([gone.pid], stop_after=None)
    assert state == "gone"
    assert seconds < 1.0
