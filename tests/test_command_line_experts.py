"""Experts from the command line (``--expert.path``, ``--expert.type``), with a policy trained here.

The expert policy is a small ``mtdagger`` policy trained by stock ``lerobot-train`` on the toy suite's
privileged state (position, goal, wind) as ``observation.state``, labelled by the scripted expert: what
an RL expert trained on the privileged state looks like to the toolkit.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import numpy as np
import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.experts import LeRobotPolicyExpert, make_expert, register_expert_type
from lerobot_mtdagger.experts.command_line import command_line_experts
from lerobot_mtdagger.utils.errors import UserError
from tests.conftest import lerobot_train

TOY = ["--suite.name=toy", "--dagger.rounds=1", "--dagger.initial_demos=2", "--dagger.budget_per_task=2"]
TOY += ["--rollout.eval_episodes=2", "--training.steps_per_round=5", "--policy.batch_size=16"]
TOY += ["--rollout.workers=0", "--progress=false"]


def _record_privileged_dataset(root: Path) -> None:
    """The scripted toy expert's episodes, observed through the privileged state, every task."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    suite = make_suite("toy")
    features = {
        "observation.state": {"dtype": "float32", "shape": (6,), "names": None},
        "action": {"dtype": "float32", "shape": (2,), "names": None},
    }
    dataset = LeRobotDataset.create(
        repo_id="local/privileged",
        fps=10,
        features=features,
        root=root,
        use_videos=False,
        video_backend="pyav",
    )
    dataset.meta.save_episode_tasks(suite.task_names)
    for task in suite.task_names:
        env, expert = suite.make_env(task), make_expert(suite, task)
        for seed in range(6):
            _, info = env.reset(seed=seed)
            for _ in range(20):
                state = info["privileged_state"].astype(np.float32)
                action = expert.act(state)
                dataset.add_frame({"observation.state": state, "action": action, "task": task})
                _, _, terminated, truncated, info = env.step(action)
                if terminated or truncated:
                    break
            dataset.save_episode()
    dataset.finalize()


@pytest.fixture(scope="module")
def expert_policy(tmp_path_factory) -> Path:
    """A multitask expert policy folder acting on the toy suite's privileged state."""
    folder = tmp_path_factory.mktemp("expert")
    _record_privileged_dataset(folder / "data")
    return lerobot_train(folder / "data", folder / "train", steps=60, repo_id="local/privileged")


def _run(tmp_path, name: str, *options: str) -> Path:
    out = tmp_path / name
    assert main(["run", *TOY, *options, f"--output_dir={out}"]) == 0
    return out


def test_a_multitask_policy_folder_labels_every_task(expert_policy):
    suite = command_line_experts(make_suite("toy"), str(expert_policy), None)
    for task in suite.task_names:
        expert = make_expert(suite, task)
        assert isinstance(expert.expert, LeRobotPolicyExpert) and expert.expert.task == task
        env = suite.make_env(task)
        _, info = env.reset(seed=3)
        action = expert.act(info["privileged_state"])
        assert action.shape == (2,) and np.all(np.isfinite(action))


def test_a_run_with_a_policy_expert_records_it_and_resumes_only_with_it(expert_policy, tmp_path, capsys):
    out = _run(tmp_path, "run", f"--expert.path={expert_policy}")
    assert json.loads((out / "config.json").read_text())["expert"]["path"] == str(expert_policy)
    record = json.loads((out / "rounds" / "round-000" / "meta" / "mtdagger.json").read_text())
    assert record["config"]["expert"]["path"] == str(expert_policy)
    assert main(["run", *TOY, "--dagger.rounds=2", f"--output_dir={out}", "--resume=true"]) == 2
    assert "expert.path" in capsys.readouterr().err
    options = [*TOY, "--dagger.rounds=2", f"--expert.path={expert_policy}", f"--output_dir={out}"]
    assert main(["run", *options, "--resume=true"]) == 0


def test_one_policy_folder_per_task(expert_policy, tmp_path, capsys):
    per_task = tmp_path / "experts"
    for task in make_suite("toy").task_names:
        shutil.copytree(expert_policy, per_task / task)
    _run(tmp_path, "run", f"--expert.path={per_task}")
    shutil.rmtree(per_task / "toy-right")
    out = tmp_path / "missing"
    assert main(["run", *TOY, f"--expert.path={per_task}", f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err
    assert "has no expert for the tasks ['toy-right']" in error and len(error.strip().splitlines()) == 1
    assert not out.exists()


def test_a_policy_on_another_input_is_refused_before_anything_is_written(tmp_path, capsys):
    student = _run(tmp_path, "student") / "policies" / "round-000"  # reads the 2-d position, not 6-d
    out = tmp_path / "out"
    assert main(["run", *TOY, f"--expert.path={student}", f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err
    assert "reads a observation.state of size 2, but this suite's privileged state has size 6" in error
    assert not out.exists()


@pytest.mark.parametrize(
    ("make_folder", "message"),
    [
        (lambda root: root / "nothing-here", "is not a folder"),
        (lambda root: (root / "empty").mkdir() or root / "empty", "has no expert for the tasks"),
    ],
)
def test_a_path_that_is_no_expert_is_refused_in_one_line(tmp_path, capsys, make_folder, message):
    out = tmp_path / "out"
    assert main(["run", *TOY, f"--expert.path={make_folder(tmp_path)}", f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err
    assert message in error and len(error.strip().splitlines()) == 1 and not out.exists()


def test_an_expert_type_by_entry_point_or_registered_name(tmp_path, capsys):
    _run(tmp_path, "entry", "--expert.type=lerobot_mtdagger.experts.toy:scripted_expert")
    calls = []

    def counting(suite, task):
        calls.append(task)
        return make_expert(suite.with_experts({}), task).expert

    register_expert_type("counting-toy", counting)
    _run(tmp_path, "registered", "--expert.type=counting-toy")
    assert calls == make_suite("toy").task_names
    for bad in ("no-such-type", "lerobot_mtdagger.experts.toy:nothing"):
        assert main(["run", *TOY, f"--expert.type={bad}", f"--output_dir={tmp_path / 'bad'}"]) == 2
        assert "is neither a registered expert type" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()


@pytest.mark.parametrize(
    ("type_name", "message"),
    [
        ("builtins:len", "is not a factory(suite, task)"),  # imports, but cannot take (suite, task)
        ("builtins:slice", "gave a slice for the task"),  # a factory that gives no expert
    ],
)
def test_an_expert_type_that_gives_no_expert_is_refused_in_one_line(tmp_path, capsys, type_name, message):
    out = tmp_path / "out"
    assert main(["run", *TOY, f"--expert.type={type_name}", f"--output_dir={out}"]) == 2
    error = capsys.readouterr().err
    assert message in error and "factory(suite, task)" in error, error
    assert len(error.strip().splitlines()) == 1 and not out.exists()


def test_path_and_type_together_are_refused(tmp_path, capsys):
    args = ["--expert.type=x:y", f"--expert.path={tmp_path}", f"--output_dir={tmp_path / 'out'}"]
    assert main(["run", *TOY, *args]) == 2
    assert "give one of them" in capsys.readouterr().err


def test_command_line_experts_leave_the_suite_alone_when_none_is_named():
    suite = make_suite("toy")
    assert command_line_experts(suite, None, None) is suite
    with pytest.raises(UserError, match="not a folder"):
        command_line_experts(suite, "/nonexistent/experts", None)
