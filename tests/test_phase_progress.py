"""A training phase's saved progress: a phase cut part-way resumes from it and ends as the phase that
was never cut (weights, losses, passes), a run killed mid-phase resumes to the uninterrupted run, and
progress that is of another phase or unreadable is discarded with a warning."""

from __future__ import annotations

import dataclasses
import json
import logging
import subprocess
import sys
import time
from pathlib import Path

import pytest
import torch

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.training.phase_progress import PhaseProgress, phase_key
from lerobot_mtdagger.runner.training.plateau import PlateauStop
from lerobot_mtdagger.runner.training.steps import StepOptions, train_phase
from lerobot_mtdagger.utils.parsing import parse_options
from tests.helpers import kill_9_and_check_workers_end
from tests.test_toy import TOY_RUN
from tests.test_train import normalised, small_policy, synthetic_data

EVERY_INTERVAL = 1e-9
"""``every_s`` that saves the progress at the start of every log interval."""


class CutError(Exception):
    """Stands for the end of a process part-way through a phase."""


def dropout_policy() -> MTDAggerPolicy:
    """A small policy that draws from the global random state at every step (dropout, task dropout)."""
    return small_policy(dropout=0.2, task_dropout=0.3)


def phase(
    path: Path | None, cut_after: int | None = None, key: dict | None = None, steps: int = 60, **options
):
    """A phase (log interval 10), its progress at ``path``; CutError after ``cut_after`` steps."""
    data = synthetic_data()
    policy = dropout_policy()
    train_index = torch.arange(len(data))
    step_options = StepOptions(steps=steps, batch_size=64, lr=1e-3, seed=0, log_interval=10, **options)
    if path is not None:
        key = key or phase_key(1, "mtdagger", step_options, train_index)
        step_options = dataclasses.replace(step_options, progress=PhaseProgress(path, key, EVERY_INTERVAL))

    def on_step(done: int, _loss: float) -> None:
        if cut_after is not None and done >= cut_after:
            raise CutError

    result = train_phase(
        policy, normalised(data, policy), train_index, torch.arange(0, len(data), 3), step_options, on_step
    )
    return policy, result


def assert_same_weights(first: MTDAggerPolicy, second: MTDAggerPolicy) -> None:
    weights = second.state_dict()
    for name, tensor in first.state_dict().items():
        assert torch.equal(tensor, weights[name]), name


@pytest.mark.parametrize(
    "options",
    [{}, {"sampling": "balanced", "lr_schedule": "cosine"}],
    ids=["uniform-constant", "balanced-cosine"],
)
def test_a_phase_cut_part_way_resumes_from_its_progress_to_the_uninterrupted_phase(tmp_path, options):
    reference_policy, reference = phase(None, **options)
    path = tmp_path / "round-001.pt"
    with pytest.raises(CutError):
        phase(path, cut_after=30, **options)  # saved at the start of steps 10 and 20; cut after 30
    assert torch.load(path, weights_only=True)["done"] == 20
    policy, resumed = phase(path, **options)
    assert resumed.resumed_after_steps == [20] and resumed.steps == 60
    assert dataclasses.replace(resumed, resumed_after_steps=[]) == reference  # losses, passes, tail
    assert_same_weights(policy, reference_policy)


def test_a_phase_resumed_twice_lists_both_resumes_and_still_ends_as_the_uninterrupted_one(tmp_path):
    """The second cut comes after the last step: the last 5 steps' losses join the 5 saved before."""
    reference_policy, reference = phase(None, steps=65)
    path = tmp_path / "round-001.pt"
    with pytest.raises(CutError):
        phase(path, cut_after=20, steps=65)
    with pytest.raises(CutError):
        phase(path, cut_after=65, steps=65)
    policy, resumed = phase(path, steps=65)
    assert resumed.resumed_after_steps == [10, 60]
    assert dataclasses.replace(resumed, resumed_after_steps=[]) == reference
    assert_same_weights(policy, reference_policy)


@pytest.mark.parametrize("bad", ["another phase", "unreadable"])
def test_progress_of_another_phase_or_unreadable_is_discarded_and_the_phase_starts_over(
    tmp_path, caplog, bad
):
    reference_policy, reference = phase(None)
    path = tmp_path / "round-001.pt"
    with pytest.raises(CutError):
        phase(path, cut_after=30, key={"round": 7})
    if bad == "unreadable":
        path.write_bytes(b"cut off while written")
    with caplog.at_level(logging.WARNING, logger="lerobot_mtdagger"):
        policy, result = phase(path)
    assert f"Discarding {path}" in caplog.text and "the phase starts over" in caplog.text
    assert result == reference and result.resumed_after_steps == []
    assert_same_weights(policy, reference_policy)


def test_a_plateau_phase_and_every_s_zero_never_save_progress(tmp_path):
    data = synthetic_data()
    policy = dropout_policy()
    train_index = torch.arange(0, len(data), 2)
    plateau = PlateauStop(index=torch.arange(1, len(data), 2), every=10, patience=100)
    options = StepOptions(steps=40, batch_size=64, lr=1e-3, seed=0, log_interval=10, plateau=plateau)
    saved = tmp_path / "plateau.pt"
    options = dataclasses.replace(options, progress=PhaseProgress(saved, {"round": 0}, EVERY_INTERVAL))
    train_phase(policy, normalised(data, policy), train_index, torch.arange(9), options)
    never = tmp_path / "never.pt"
    phase_options = dataclasses.replace(
        options, plateau=None, progress=PhaseProgress(never, {"round": 0}, 0.0)
    )
    train_phase(policy, normalised(data, policy), train_index, torch.arange(9), phase_options)
    assert not saved.exists() and not never.exists()


TOY_LONG_PHASES = [*TOY_RUN, "--dagger.rounds=1", "--training.steps_per_round=1500"]
"""One DAgger round, phases of seconds so that the kill lands in one."""


def test_a_run_killed_mid_phase_resumes_from_the_saved_progress_to_the_uninterrupted_run(tmp_path):
    reference, killed = tmp_path / "reference", tmp_path / "killed"
    run(parse_options(RunConfig, [*TOY_LONG_PHASES, f"--output_dir={reference}"], "run"))
    command = [str(Path(sys.executable).parent / "lerobot-mtdagger"), "run", *TOY_LONG_PHASES]
    saving = [*command, f"--training.progress_every_s={EVERY_INTERVAL}", f"--output_dir={killed}"]
    process = subprocess.Popen(saving, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    progress = ExperimentDir(killed).phase_progress_path(1)
    deadline = time.time() + 120
    while not progress.exists() and time.time() < deadline:
        assert process.poll() is None, "the run ended before phase 1 saved its progress"
        time.sleep(0.01)
    kill_9_and_check_workers_end(process)
    assert ExperimentDir(killed).committed_phases() == [0], "the kill should have cut phase 1"
    subprocess.run([*saving, "--resume=true"], check=True, capture_output=True)

    experiment = ExperimentDir(killed)
    assert verify_experiment(experiment) == (2, 2, [])
    assert not progress.parent.exists()  # deleted at commit
    records = {
        r: json.loads((ExperimentDir(r).policy_root(1) / "training.json").read_text())
        for r in (reference, killed)
    }
    resumed_after = records[killed].pop("resumed_after_steps")
    assert records[reference].pop("resumed_after_steps") == [] and len(resumed_after) == 1
    assert 0 < resumed_after[0] < 1500
    for record in records.values():
        for volatile in ("timings", "files"):
            record.pop(volatile)
    assert records[reference] == records[killed]
    for k in (0, 1):
        weights = [
            MTDAggerPolicy.from_pretrained(str(ExperimentDir(r).policy_root(k))) for r in (reference, killed)
        ]
        assert_same_weights(*weights)
