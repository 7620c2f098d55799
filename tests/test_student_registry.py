"""A student from outside the package: registered under its own ``--policy.type`` and run by ``run``.

``CopyStudent`` is the ``mtdagger`` student under another name, with its own options class; it
counts the seam's calls, so the test sees the runner train and evaluate through it.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.checkpoints import check_local_policy
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.runner import student as student_registry
from lerobot_mtdagger.runner.policy_options import PolicyOptions
from lerobot_mtdagger.runner.student import Student, get_student, register_student, student_names
from lerobot_mtdagger.students.mtdagger import MTDAggerStudent
from lerobot_mtdagger.utils.errors import UserError
from tests.helpers import TINY_ROUND

NAME = "mtdagger-copy"

TINY_RUN = ["--suite.name=toy", *TINY_ROUND]


@dataclass
class CopyOptions(PolicyOptions):
    """``mtdagger``'s options, under the copy's own type."""


class CopyStudent(MTDAggerStudent):
    """The ``mtdagger`` student registered as another type, counting the seam's calls."""

    calls: list[str] = []  # noqa: RUF012  (shared by the registry's one instance and the test)

    def options_class(self) -> type:
        return CopyOptions

    def phase_ops(self, policy: Any, data: Any, options: Any) -> Any:
        self.calls.append("phase_ops")
        return super().phase_ops(policy, data, options)

    def make_runner(self, policy: Any, preprocessor: Any, postprocessor: Any) -> Any:
        self.calls.append("make_runner")
        return super().make_runner(policy, preprocessor, postprocessor)


@pytest.fixture
def copy_registered(monkeypatch):
    """``CopyStudent`` registered for one test (the registry is restored after it)."""
    monkeypatch.setattr(student_registry, "STUDENTS", student_registry.STUDENTS.copy())
    register_student(NAME, CopyStudent)
    CopyStudent.calls.clear()
    yield
    assert NAME in student_names()


def test_a_student_from_outside_the_package_runs_a_dagger_round(tmp_path, copy_registered):
    root = tmp_path / "copy"
    assert main(["run", *TINY_RUN, f"--policy.type={NAME}", f"--output_dir={root}"]) == 0
    experiment = ExperimentDir(root)
    assert experiment.committed_rounds() == [0, 1]
    assert experiment.read_phase_record(1).steps == 5
    check_local_policy(experiment.policy_root(1))  # saved as an mtdagger policy
    assert json.loads((root / "config.json").read_text())["policy"]["type"] == NAME
    assert CopyStudent.calls.count("phase_ops") == 2 and CopyStudent.calls.count("make_runner") == 2


def test_the_registry_refuses_an_unknown_type_a_taken_name_and_a_non_student(capsys, copy_registered):
    assert main(["run", "--policy.type=pi0", "--suite.name=toy"]) == 2
    error = capsys.readouterr().err.strip()
    assert len(error.splitlines()) == 1
    assert "Unknown --policy.type 'pi0'" in error and "mtdagger, act, diffusion" in error and NAME in error
    with pytest.raises(UserError, match="registered students"):
        get_student("pi0")
    with pytest.raises(UserError, match="already registered"):
        register_student("act", CopyStudent)
    with pytest.raises(TypeError, match="Student subclass"):
        register_student("not-a-student", object)  # type: ignore[arg-type]


def test_every_builtin_student_meets_the_contract():
    assert student_names() == ["mtdagger", "act", "diffusion"]  # nothing left registered by the tests
    for name in ("mtdagger", "act", "diffusion"):
        student = get_student(name)
        assert isinstance(student, Student) and student.name == name
    assert get_student("mtdagger").lr_option == "lr" and get_student("act").lr_option == "optimizer_lr"
    assert get_student("act").options_class().__name__ == "ACTConfigStudent"
