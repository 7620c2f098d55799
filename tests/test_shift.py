"""Covariate shift measurement (``shift.measure_shift``, ``lerobot-mtdagger shift``) on the toy suite."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

from lerobot_mtdagger.analysis.shift import ShiftResult, measure_shift, shift_ratio
from lerobot_mtdagger.cli import main
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.envs.toy import START_BOX, TOY_TASKS
from lerobot_mtdagger.experts.toy import ToyExpert
from lerobot_mtdagger.runner.rollout.evaluate import evaluate
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers

EXPERT = ToyExpert()


@pytest.fixture(scope="module")
def suite():
    return make_suite("toy")


def expert_action(observation: dict, task_name: str) -> np.ndarray:
    """The toy expert's action, from the learner's view (position) and the task's known goal and wind."""
    task = TOY_TASKS[task_name]
    return EXPERT.act(np.concatenate([observation["observation.state"], task.goal, task.wind]))


def copy_expert(observations, tasks):
    """A learner that acts exactly as the expert."""
    return np.stack([expert_action(o, t) for o, t in zip(observations, tasks, strict=True)])


def biased(observations, tasks):
    """The expert's action moved 0.1 towards 0 in each dimension: the same error everywhere, never clipped."""
    actions = copy_expert(observations, tasks)
    return np.where(actions >= 0.0, actions - np.float32(0.1), actions + np.float32(0.1))


def huge(observations, tasks):
    """Actions far outside the action space, as a policy fed a state far outside its data may output."""
    return np.full((len(observations), 2), 1e6, dtype=np.float32)


def lost_outside_the_start_box(observations, tasks):
    """The expert inside the start box, nothing outside: it stops at the box's edge and stays there."""
    actions = copy_expert(observations, tasks)
    outside = np.array([np.abs(o["observation.state"]).max() > START_BOX for o in observations])
    actions[outside] = 0.0
    return actions


def shift_of(suite, policy, episodes=4, seed=0) -> ShiftResult:
    with EnvWorkers(suite, 0) as workers:
        return measure_shift(workers, policy, episodes, seed)


def test_a_policy_that_acts_as_the_expert_has_no_error_anywhere(suite):
    result = shift_of(suite, copy_expert)
    assert result.success == [1.0, 1.0, 1.0]
    assert result.own_error == pytest.approx([0.0] * 3, abs=1e-9)
    assert result.expert_error == pytest.approx([0.0] * 3, abs=1e-9)
    assert result.own_error_failed == [None, None, None]


def test_a_policy_wrong_everywhere_alike_meets_no_shift(suite):
    result = shift_of(suite, biased)
    assert result.own_error == pytest.approx([0.02] * 3) and result.expert_error == pytest.approx([0.02] * 3)
    assert np.allclose(result.own_error_by_dimension, 0.01) and np.allclose(
        result.expert_error_by_dimension, 0.01
    )
    assert result.ratio == pytest.approx([1.0] * 3) and result.median_ratio == pytest.approx(1.0)


def test_actions_are_clipped_to_the_action_space_as_the_env_clips_what_it_executes(suite):
    result = shift_of(suite, huge, episodes=2)
    assert all(0.0 < error <= 2 * 2.0**2 for error in [*result.own_error, *result.expert_error])


def test_a_policy_lost_off_the_experts_states_shows_its_shift_on_its_failed_episodes(suite):
    result = shift_of(suite, lost_outside_the_start_box)
    assert result.success == [0.0, 0.0, 0.0], "it stops at the start box, short of every goal"
    assert result.own_error_succeeded == [None, None, None]
    assert result.own_error_failed == result.own_error
    assert [sum(dims) for dims in result.own_error_by_dimension] == pytest.approx(result.own_error)
    assert all(ratio > 2.0 for ratio in result.ratio), result.ratio
    assert result.mean_ratio > 2.0 and result.median_ratio > 2.0


def test_the_policys_success_is_evaluations_on_the_same_episodes(suite):
    def half_the_time_lost(observations, tasks):
        lost = np.array([task == "toy-left" for task in tasks])
        return np.where(
            lost[:, None], lost_outside_the_start_box(observations, tasks), copy_expert(observations, tasks)
        )

    result = shift_of(suite, half_the_time_lost, episodes=3, seed=7)
    with EnvWorkers(suite, 0) as workers:
        evaluation, _ = evaluate(workers, half_the_time_lost, 3, seed=7)
    assert result.success == evaluation.success == [0.0, 1.0, 1.0]


def test_the_measurement_is_reproducible_under_its_seed(suite):
    # The lost policy's error depends on where it starts (how long it stands at the box's edge).
    first = shift_of(suite, lost_outside_the_start_box, seed=3)
    again = shift_of(suite, lost_outside_the_start_box, seed=3)
    other = shift_of(suite, lost_outside_the_start_box, seed=4)
    assert first.to_dict() == again.to_dict()
    assert first.own_error != other.own_error


def test_ratios_without_any_error_on_expert_states():
    assert shift_ratio(0.0, 0.0) == 1.0 and math.isinf(shift_ratio(0.5, 0.0))
    result = ShiftResult(["a"], [0.0], [0.5], [None], [0.5], [0.0], [[0.5]], [[0.0]], episodes=1, seed=0)
    assert result.to_dict()["ratio"] == [None] and result.to_dict()["mean_ratio"] is None


def test_zero_episodes_is_refused(suite):
    with pytest.raises(ValueError, match="episodes_per_task must be > 0"):
        shift_of(suite, copy_expert, episodes=0)


def test_the_shift_command_measures_a_trained_policy_and_writes_json(tmp_path, capsys):
    run_dir = tmp_path / "run"
    small = [
        "--dagger.rounds=1",
        "--dagger.initial_demos=2",
        "--dagger.budget_per_task=1",
        "--training.steps_per_round=30",
        "--rollout.eval_episodes=2",
    ]
    network = ["--policy.batch_size=32", "--policy.state_hidden_dims=[32]", "--policy.head_hidden_dims=[32]"]
    options = ["--suite.name=toy", "--mode=bc", *small, *network, "--rollout.workers=0", "--progress=false"]
    assert main(["run", *options, f"--output_dir={run_dir}"]) == 0
    capsys.readouterr()
    output = tmp_path / "shift.json"
    policy = run_dir / "policies" / "round-000"
    assert (
        main(
            [
                "shift",
                f"--policy_path={policy}",
                "--suite.name=toy",
                "--episodes=2",
                "--workers=0",
                f"--output={output}",
            ]
        )
        == 0
    )
    printed = capsys.readouterr().out
    saved = json.loads(output.read_text())
    assert saved["task_names"] == list(TOY_TASKS) and saved["episodes"] == 2
    assert all(error > 0 for error in saved["expert_error"])
    assert (
        "median task's own/expert ratio" in printed
        and "per action dimension" in printed
        and all(task in printed for task in TOY_TASKS)
    )


def test_the_shift_command_refuses_a_missing_policy_naming_the_fix(tmp_path, capsys):
    assert main(["shift", f"--policy_path={tmp_path / 'nowhere'}", "--suite.name=toy"]) == 2
    assert "does not exist" in capsys.readouterr().err
