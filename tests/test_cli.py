"""Smoke tests of the ``lerobot-mtdagger`` command and the synthetic-task simulation."""

from __future__ import annotations

import fnmatch
import json
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import numpy as np
import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets_cards import card_template
from lerobot_mtdagger.scheduler import allocation_mismatches, make_scheduler
from lerobot_mtdagger.studies.simulate import SyntheticTasks, simulate


def test_console_script_demo_runs_and_writes_records(tmp_path):
    output = tmp_path / "rounds.json"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "lerobot_mtdagger.cli",
            "demo",
            "--scheduler.type=gain",
            "--rounds=3",
            f"--output={output}",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "round 3: allocation" in result.stdout
    records = json.loads(output.read_text())
    assert [r["round"] for r in records] == [1, 2, 3]
    for record in records:
        assert sum(record["allocation"]["episodes_per_task"]) == 30
        assert allocation_mismatches(record["allocation"]) == []


def test_help_and_unknown_command(capsys):
    assert main([]) == 0
    assert "demo" in capsys.readouterr().out
    assert main(["train-everything"]) == 2
    assert "unknown command 'train-everything'" in capsys.readouterr().err


def test_demo_rejects_bad_options_with_the_fields_message(capsys):
    assert main(["demo", "--num_tasks=0"]) == 2
    assert "num_tasks must be >= 1, got 0" in capsys.readouterr().err
    assert main(["demo", "--scheduler.temperature=0"]) == 2
    assert "scheduler.temperature must be a finite number > 0" in capsys.readouterr().err


@pytest.mark.parametrize("method", ["need", "gain"])
def test_performance_aware_methods_favour_hard_synthetic_tasks(method):
    hard_share = {}
    for name in (method, "uniform"):
        tasks = SyntheticTasks.spread(8, easiest=1.0, hardest=40.0)
        simulate(make_scheduler(name, 8), tasks, rounds=5, budget=24, initial_demos=3, seed=0)
        hard_share[name] = tasks.demos[-3:].sum() / tasks.demos.sum()
    assert hard_share[method] > hard_share["uniform"]


def test_simulation_is_reproducible_under_a_seed():
    def run():
        tasks = SyntheticTasks.spread(5)
        history = simulate(make_scheduler("need", 5), tasks, rounds=4, budget=15, initial_demos=2, seed=7)
        return [r.allocation.episodes_per_task for r in history]

    assert run() == run()
    assert np.all(np.asarray(run()).sum(axis=1) == 15)


def test_dataset_card_template_ships_with_the_package(tmp_path):
    assert "{{ allocation_table }}" in card_template()  # the importable package (here: the source tree)

    # The built distribution: a wheel of a copy of the project (building in place would write build/ into
    # the checkout and could package stale files from it). The copy skips what .gitignore ignores.
    repo = Path(__file__).resolve().parents[1]
    ignored = [line.rstrip("/") for line in (repo / ".gitignore").read_text().split() if line.strip()]
    source = tmp_path / "source"
    shutil.copytree(repo, source, ignore=shutil.ignore_patterns(".git", *ignored))
    pip_wheel = [sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "--no-build-isolation"]
    subprocess.run([*pip_wheel, "-w", str(tmp_path / "dist")], check=True, capture_output=True, text=True)
    (wheel,) = (tmp_path / "dist").glob("lerobot_mtdagger-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        cards = fnmatch.filter(archive.namelist(), "lerobot_mtdagger/datasets_cards/*.md")
        assert "lerobot_mtdagger/datasets_cards/mtdagger_card.md" in cards, f"cards in the wheel: {cards}"
        card = archive.read("lerobot_mtdagger/datasets_cards/mtdagger_card.md").decode("utf-8")
    assert "{{ allocation_table }}" in card


@pytest.mark.parametrize(
    ("inputs", "given", "expected"),
    [
        ({"observation.state": (4,), "observation.pointcloud": (512, 3)}, {}, ("pointcloud", 512, 84)),
        ({"observation.state": (7,), "observation.image": (3, 64, 64)}, {}, ("rgb", 1024, 64)),
        ({"observation.state": (39,)}, {}, ("state", 1024, 84)),
        ({"observation.pointcloud": (512, 3)}, {"num_points": 256}, ("pointcloud", 256, 84)),
    ],
)
def test_eval_takes_the_observation_options_the_policy_was_trained_with(inputs, given, expected):
    """A point-cloud policy evaluates without --suite.obs_mode / --suite.num_points; what is given wins."""
    from types import SimpleNamespace

    from lerobot.configs.types import FeatureType, PolicyFeature

    from lerobot_mtdagger.cli import EvalConfig, observation_options
    from lerobot_mtdagger.envs import SuiteConfig

    features = {
        key: PolicyFeature(FeatureType.VISUAL if "image" in key else FeatureType.STATE, shape)
        for key, shape in inputs.items()
    }
    runner = SimpleNamespace(policy=SimpleNamespace(config=SimpleNamespace(input_features=features)))
    options = observation_options(runner, EvalConfig(policy_path="p", suite=SuiteConfig(**given)).suite)
    assert (options["obs_mode"], options["num_points"], options["image_size"]) == expected
