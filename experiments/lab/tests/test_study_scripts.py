"""``experiments/with_studies_paused.sh``: a command run with the studies' runs paused, always resumed."""

from __future__ import annotations

import re
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from lerobot_mtdagger.studies.launchers import Job, job_command

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
