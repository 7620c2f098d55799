"""Smoke tests of the ``lerobot-mtdagger`` command and the synthetic-task simulation."""

from __future__ import annotations

import json
import subprocess
import sys

import numpy as np
import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets_cards import card_template
from lerobot_mtdagger.scheduler import allocation_mismatches, make_scheduler
from lerobot_mtdagger.simulate import SyntheticTasks, simulate


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


def test_dataset_card_template_ships_with_the_package():
    assert "{{ allocation_table }}" in card_template()
