"""kill -9 campaign (slow set): a small MetaWorld run killed at 20 seeded moments spread over its whole
length, each resumed and compared with an uninterrupted run, record by record and file by file.

The moments are drawn (seed ``CAMPAIGN_SEED``) from the events of a run, in order: each is "the
moment a path appears, plus a seeded delay", so every part of every round is hit: expert collection,
parallel DAgger collection (two env workers), writing a round dataset, its commit, training,
evaluation, and a phase's commit. After each resume every committed round record, every dataset
file's sha256 (recorded at commit), every policy file's sha256 (the weights and processors) and
every phase record must equal the uninterrupted run's, except wall times and the output folder.
What each kill hit is recorded in ``docs/reliability.md``.
"""

from __future__ import annotations

import json
import os
import subprocess
import time
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from tests.helpers import kill_9_and_check_workers_end
from tests.test_dagger import _cli

pytestmark = pytest.mark.slow

CAMPAIGN_SEED = 20261122
MOMENTS = 20
MAX_DELAY_S = 0.4
EVENTS: list[tuple[str, str]] = [
    ("run.log", "round-0 expert collection"),
    ("rounds/.staging/round-000", "writing round 0"),
    ("rounds/round-000", "just after round 0's commit: training phase 0"),
    ("policies/.staging/round-000/config.json", "saving / evaluating phase 0"),
    ("policies/round-000", "just after phase 0's commit: round-1 parallel collection"),
    ("rounds/.staging/round-001", "writing round 1"),
    ("rounds/round-001", "just after round 1's commit: training phase 1"),
    ("policies/.staging/round-001/config.json", "saving / evaluating phase 1"),
    ("policies/round-001", "just after phase 1's commit: round-2 parallel collection"),
    ("rounds/.staging/round-002", "writing round 2"),
    ("rounds/round-002", "just after round 2's commit: training phase 2"),
    ("policies/.staging/round-002/config.json", "saving / evaluating phase 2"),
]
"""(path whose appearance starts the delay, what the run is doing then), in the order of a run."""


def campaign_moments(seed: int = CAMPAIGN_SEED) -> list[tuple[int, float]]:
    """20 (event index, delay) pairs: every event once, the rest drawn; sorted along the run."""
    rng = np.random.default_rng(seed)
    events = [*range(len(EVENTS)), *rng.integers(0, len(EVENTS), MOMENTS - len(EVENTS)).tolist()]
    delays = rng.uniform(0.0, MAX_DELAY_S, MOMENTS).round(3).tolist()
    return sorted(zip(events, delays, strict=True))


def snapshot(root: Path) -> dict[str, Any]:
    """Everything a run committed, without wall times, the output folder and the resume flag."""
    experiment = ExperimentDir(root)
    rounds = {}
    for k in experiment.committed_rounds():
        record = experiment.read_round_record(k).to_dict()
        record["config"] = {**record["config"], "output_dir": None, "resume": None}
        rounds[k] = record
    phases = {}
    for k in experiment.committed_phases():
        record = experiment.read_phase_record(k).to_dict()
        record["timings"] = None
        phases[k] = record
    return {"rounds": rounds, "phases": phases}


def what_was_hit(root: Path) -> str:
    """The run's state on disk right after the kill."""
    staged = sorted(str(p.relative_to(root)) for p in root.glob("*/.staging/*"))
    committed = len(ExperimentDir(root).committed_rounds()), len(ExperimentDir(root).committed_phases())
    return f"{committed[0]} rounds and {committed[1]} phases committed; staging: {staged or 'none'}"


@pytest.fixture(scope="module")
def reference(tmp_path_factory) -> dict[str, Any]:
    root = tmp_path_factory.mktemp("campaign") / "reference"
    subprocess.run(_cli(root, "--scheduler.type=need"), check=True, capture_output=True)
    return snapshot(root)


def kill_at(root: Path, path: str, delay: float) -> tuple[bool, str]:
    """Starts the run, kills it (SIGKILL) ``delay`` s after ``path`` appears; whether it was killed."""
    process = subprocess.Popen(
        _cli(root, "--scheduler.type=need"), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.time() + 300
    while not (root / path).exists() and process.poll() is None and time.time() < deadline:
        time.sleep(0.01)
    time.sleep(delay)
    if process.poll() is not None:
        return False, "the run had finished"
    kill_9_and_check_workers_end(process)
    return True, what_was_hit(root)


@pytest.mark.parametrize(("event", "delay"), campaign_moments())
def test_kill_9_at_a_seeded_moment_then_resume_equals_the_uninterrupted_run(
    tmp_path, reference, event, delay
):
    root = tmp_path / "killed"
    killed, hit = kill_at(root, EVENTS[event][0], delay)
    log = Path(os.environ.get("MTDAGGER_CAMPAIGN_LOG", tmp_path / "campaign.jsonl"))
    with log.open("a") as handle:
        handle.write(
            json.dumps({"event": EVENTS[event][1], "delay_s": delay, "killed": killed, "hit": hit}) + "\n"
        )
    if not killed:  # nothing was interrupted: reported as skipped, never as a kill survived
        pytest.skip(f"the run finished before the kill {delay:.2f} s after {EVENTS[event][0]} appeared")
    subprocess.run(_cli(root, "--scheduler.type=need", "--resume=true"), check=True, capture_output=True)
    assert verify_experiment(ExperimentDir(root)) == (3, 3, [])
    assert differences(snapshot(root), reference) == []


def differences(ours: Any, theirs: Any, where: str = "") -> list[str]:
    """Paths at which two snapshots differ (readable failures)."""
    if isinstance(ours, dict) and isinstance(theirs, dict):
        keys = sorted(set(ours) | set(theirs), key=str)
        return [d for key in keys for d in differences(ours.get(key), theirs.get(key), f"{where}/{key}")]
    return [] if ours == theirs else [where]
