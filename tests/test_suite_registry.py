"""Suites register by name: one from outside the package runs DAgger from the command line."""

from __future__ import annotations

import json
import sys
import textwrap

import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.envs import (
    SUITE_NAMES,
    SuiteOptions,
    make_suite,
    register_suite,
    registry,
    suite_names,
)
from lerobot_mtdagger.envs.toy import ToySuite, ToyTask, build_toy_suite
from lerobot_mtdagger.utils.errors import UserError

CORNER_TASKS = (
    ToyTask("corner-up", goal=(0.5, 0.5)),
    ToyTask("corner-down", goal=(-0.5, -0.5), wind=(0.01, 0.0)),
)
"""The tasks of a suite defined here, outside the package: two toy tasks of our own."""

TINY_RUN = [
    "--dagger.rounds=1",
    "--dagger.initial_demos=1",
    "--dagger.budget_per_task=1",
    "--training.steps_per_round=5",
    "--rollout.eval_episodes=1",
    "--rollout.max_steps=40",
    "--rollout.workers=0",
    "--policy.batch_size=8",
    "--policy.state_hidden_dims=[16]",
    "--policy.head_hidden_dims=[16]",
    "--policy.task_embedding_dim=4",
    "--progress=false",
]


class CornerSuite(ToySuite):
    """The toy point mass sent to two corners (the toy suite's expert family, so its expert)."""

    name = "toy-corners"


def corner_suite(options: SuiteOptions) -> CornerSuite:
    """The factory of ``toy-corners``: both corners unless tasks are given."""
    options.refuse_placement()
    task_names = options.task_list([task.name for task in CORNER_TASKS])
    return CornerSuite(task_names, options.observation, options.max_episode_steps, tasks=CORNER_TASKS)


@pytest.fixture
def own_registry(monkeypatch):
    """The registry as the package leaves it, restored after the test (registrations are global)."""
    monkeypatch.setattr(registry, "SUITES", registry.SUITES.copy())


def test_a_suite_registered_outside_the_package_runs_a_dagger_round(tmp_path, own_registry):
    register_suite("toy-corners", corner_suite)
    assert make_suite("toy-corners").task_names == ["corner-up", "corner-down"]
    out = tmp_path / "corners"
    assert main(["run", "--suite.name=toy-corners", *TINY_RUN, f"--output_dir={out}"]) == 0
    experiment = ExperimentDir(out)
    assert experiment.committed_rounds() == [0, 1] and experiment.committed_phases() == [0, 1]
    assert verify_experiment(experiment) == (2, 2, [])
    record = experiment.read_round_record(1)
    assert record.task_names == ["corner-up", "corner-down"] and sum(record.episodes_per_task) == 2
    assert json.loads((out / "config.json").read_text())["suite"]["name"] == "toy-corners"


def test_suite_module_registers_suites_before_the_run_and_is_checked_on_resume(
    tmp_path, monkeypatch, capsys, own_registry
):
    module = "outside_suites_for_the_registry_test"
    (tmp_path / f"{module}.py").write_text(
        textwrap.dedent(
            """
            from lerobot_mtdagger.envs import register_suite
            from lerobot_mtdagger.envs.toy import build_toy_suite

            register_suite("toy-from-a-module", build_toy_suite)
            """
        )
    )
    monkeypatch.syspath_prepend(str(tmp_path))
    monkeypatch.delitem(sys.modules, module, raising=False)
    out = tmp_path / "run"
    options = ["run", "--suite.name=toy-from-a-module", *TINY_RUN, "--dagger.rounds=0", f"--output_dir={out}"]
    assert main([*options, f"--suite.module={module}"]) == 0
    assert "toy-from-a-module" in suite_names()
    assert json.loads((out / "config.json").read_text())["suite"]["module"] == module
    capsys.readouterr()
    assert main([*options, "--resume=true"]) == 2  # the module is part of the run's config
    error = capsys.readouterr().err
    assert "suite.module" in error and len(error.strip().splitlines()) == 1
    monkeypatch.delitem(sys.modules, module, raising=False)


def test_an_unknown_suite_is_refused_in_one_line_naming_the_registered_ones(tmp_path, capsys, own_registry):
    register_suite("toy-corners", corner_suite)
    out = tmp_path / "out"
    assert main(["run", "--suite.name=robosuite", *TINY_RUN, f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "Unknown suite 'robosuite'" in error and "--suite.module" in error
    assert all(name in error for name in [*SUITE_NAMES, "toy-corners"])
    assert not out.exists()


def test_an_unimportable_suite_module_is_refused_in_one_line(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", "--suite.name=toy", "--suite.module=no_such_suites", f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1 and "--suite.module=no_such_suites cannot be imported" in error
    assert main(["run", "--suite.name=toy", "--suite.module=not a module", f"--output_dir={out}"]) == 2
    assert "suite.module must be a dotted module name" in capsys.readouterr().err
    assert not out.exists()


def test_a_name_is_registered_once(own_registry):
    register_suite("toy-corners", corner_suite)
    with pytest.raises(UserError, match="A suite named 'toy-corners' is already registered"):
        register_suite("toy-corners", corner_suite)
    with pytest.raises(UserError, match="A suite named 'toy' is already registered"):
        register_suite("toy", build_toy_suite)
    with pytest.raises(TypeError, match="must be callable or a 'module:attribute' string"):
        register_suite("toy-nothing", "no entry point")
    assert "toy-nothing" not in suite_names() and suite_names()[: len(SUITE_NAMES)] == list(SUITE_NAMES)


def test_the_built_in_suites_keep_their_names_and_refuse_a_placement_they_lack():
    assert make_suite("toy").name == "toy"
    with pytest.raises(UserError, match="placement='narrow' applies to the drawers suite only"):
        make_suite("toy", placement="narrow")
    with pytest.raises(UserError, match="needs an explicit tasks"):
        make_suite("metaworld")
