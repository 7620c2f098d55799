"""LeRobot's ACT and Diffusion Policy as the DAgger student (``--policy.type=act|diffusion``).

On the toy suite (no MuJoCo) end to end: rounds and records, ``verify``, kill -9 and resume, ``eval``,
the saved policy loading with stock LeRobot; the frame windows, the one-hot task vector, the
per-episode action queues and the per-task loss on their own; bad options refused.
"""

from __future__ import annotations

import dataclasses
import hashlib
import json
import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import draccus
import numpy as np
import pytest
import torch

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.policies.task_conditioning import TASK_FEATURE, TaskOneHotProcessorStep, task_one_hot
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner, evaluate
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.runner.student import get_student
from lerobot_mtdagger.students.chunk_runner import ChunkRunner
from lerobot_mtdagger.students.lerobot import EpisodeWindows, LeRobotOps, lerobot_student_config
from lerobot_mtdagger.students.options import lerobot_students
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.parsing import parse_options

TOY_STUDENT_RUN = [
    "--suite.name=toy",
    "--dagger.rounds=2",
    "--dagger.initial_demos=2",
    "--dagger.budget_per_task=2",
    "--training.steps_per_round=40",
    "--rollout.eval_episodes=2",
    "--rollout.max_steps=40",
    "--policy.batch_size=32",
    "--progress=false",
]

TINY_ACT = [
    "--policy.type=act",
    "--policy.dim_model=32",
    "--policy.dim_feedforward=64",
    "--policy.n_heads=2",
    "--policy.n_encoder_layers=1",
    "--policy.n_vae_encoder_layers=1",
    "--policy.chunk_size=4",
    "--policy.n_action_steps=3",
    "--policy.optimizer_lr=1e-3",
]

TINY_DIFFUSION = [
    "--policy.type=diffusion",
    "--policy.down_dims=[16,32]",
    "--policy.horizon=8",
    "--policy.n_action_steps=4",
    "--policy.diffusion_step_embed_dim=16",
    "--policy.num_inference_steps=5",
    "--policy.scheduler_warmup_steps=5",
]


def student_config(output_dir: Path, *extra: str) -> RunConfig:
    return draccus.parse(RunConfig, args=[*TOY_STUDENT_RUN, f"--output_dir={output_dir}", *extra])


@pytest.fixture(scope="module")
def suite():
    return make_suite("toy")


@pytest.fixture(scope="module")
def act_run(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("act") / "run"
    run(student_config(root, *TINY_ACT, "--rollout.workers=0"))
    return root


@pytest.fixture(scope="module")
def diffusion_run(tmp_path_factory) -> Path:
    root = tmp_path_factory.mktemp("diffusion") / "run"
    run(student_config(root, *TINY_DIFFUSION, "--rollout.workers=0"))
    return root


# -------------------------------------------------------------------------------------------------
# End to end
# -------------------------------------------------------------------------------------------------


@pytest.mark.parametrize("name", ["act_run", pytest.param("diffusion_run", marks=pytest.mark.slow)])
def test_a_lerobot_student_runs_every_round_and_verifies(request, name):
    root = request.getfixturevalue(name)
    experiment = ExperimentDir(root)
    assert experiment.committed_rounds() == [0, 1, 2]
    record = experiment.read_round_record(2)
    assert record.config["policy"]["type"] == name.removesuffix("_run")
    phase = experiment.read_phase_record(2)
    assert phase.eval is not None and len(phase.eval["success"]) == 3
    assert all(loss is not None and np.isfinite(loss) for loss in phase.loss_end)
    assert phase.gain is not None and len(phase.gain) == 3
    rounds, policies, problems = verify_experiment(experiment)
    assert (rounds, policies, problems) == (3, 3, [])


def test_a_lerobot_student_learns_the_toy_tasks(act_run):
    """Not a stub: ACT trained on the toy experts beats the policy that does not move (success 0)."""
    phase = ExperimentDir(act_run).read_phase_record(2)
    assert phase.eval["mean"] >= 0.5, phase.eval


@pytest.mark.parametrize("name", ["act_run", pytest.param("diffusion_run", marks=pytest.mark.slow)])
def test_the_saved_student_loads_and_acts_with_stock_lerobot(request, name):
    from lerobot.configs.policies import PreTrainedConfig
    from lerobot.policies.factory import get_policy_class, make_pre_post_processors

    folder = ExperimentDir(request.getfixturevalue(name)).policy_root(2)
    config = PreTrainedConfig.from_pretrained(folder)
    policy = get_policy_class(config.type).from_pretrained(folder)
    preprocessor, postprocessor = make_pre_post_processors(policy.config, pretrained_path=str(folder))
    state = torch.zeros(1, policy.config.robot_state_feature.shape[0])
    batch = preprocessor({"observation.state": state, "task": "toy-right"})
    assert batch[TASK_FEATURE].tolist() == [[0.0, 1.0, 0.0]]
    action = postprocessor(policy.select_action(batch))
    assert action.shape == (1, 2) and torch.isfinite(action).all()


def test_eval_of_a_lerobot_student_reports_every_task(act_run, tmp_path):
    from lerobot_mtdagger.cli import main

    output = tmp_path / "eval.json"
    policy = ExperimentDir(act_run).policy_root(2)
    assert (
        main(
            [
                "eval",
                f"--policy_path={policy}",
                "--suite.name=toy",
                "--episodes=2",
                "--workers=0",
                f"--output={output}",
            ]
        )
        == 0
    )
    result = json.loads(output.read_text())
    assert result["task_names"] == ["toy-left", "toy-right", "toy-up-windy"]
    assert result["episodes"] == [2, 2, 2] and len(result["success"]) == 3


@pytest.mark.slow  # three ACT runs, about 25 s (tests/test_toy.py kills a run in the default suite)
def test_a_lerobot_student_resumes_after_kill_9_to_the_same_result(act_run, tmp_path):
    command = [
        str(Path(sys.executable).parent / "lerobot-mtdagger"),
        "run",
        *TOY_STUDENT_RUN,
        *TINY_ACT,
        "--rollout.workers=1",
        f"--output_dir={tmp_path / 'killed'}",
    ]
    process = subprocess.Popen(command, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    deadline = time.time() + 300
    while not (tmp_path / "killed" / "policies" / "round-000").exists() and time.time() < deadline:
        assert process.poll() is None, "the run ended before phase 0 was committed"
        time.sleep(0.05)
    assert process.poll() is None, "the run finished before it could be killed"
    os.kill(process.pid, signal.SIGKILL)
    process.wait()
    subprocess.run([*command, "--resume=true"], check=True, capture_output=True)
    assert _policy_digests(tmp_path / "killed") == _policy_digests(act_run)
    killed, reference = ExperimentDir(tmp_path / "killed"), ExperimentDir(act_run)
    for k in range(3):
        assert (
            killed.read_round_record(k).episodes_per_task == reference.read_round_record(k).episodes_per_task
        )
        assert killed.read_phase_record(k).eval["success"] == reference.read_phase_record(k).eval["success"]


def _policy_digests(root: Path) -> dict[str, str]:
    return {
        str(path.relative_to(root)): hashlib.sha256(path.read_bytes()).hexdigest()
        for path in sorted((root / "policies").glob("round-*/model.safetensors"))
    }


# -------------------------------------------------------------------------------------------------
# The pieces
# -------------------------------------------------------------------------------------------------


def test_windows_stay_inside_each_episode_and_mark_the_padding():
    episode = torch.tensor([7, 7, 7, 3, 3])
    windows = EpisodeWindows(episode, observation_deltas=[-1, 0], action_deltas=[-1, 0, 1, 2])
    chunk, pad = windows.actions(torch.tensor([0, 2, 3]))
    assert chunk.tolist() == [[0, 0, 1, 2], [1, 2, 2, 2], [3, 3, 4, 4]]
    assert pad.tolist() == [
        [True, False, False, False],
        [False, False, True, True],
        [True, False, False, True],
    ]
    assert windows.observations(torch.tensor([0, 1, 4])).tolist() == [[0, 0], [0, 1], [3, 4]]
    assert EpisodeWindows(episode, None, [0]).observations(torch.tensor([1])) is None


def test_windows_refuse_an_episode_whose_frames_are_apart():
    with pytest.raises(ValueError, match="not consecutive"):
        EpisodeWindows(torch.tensor([1, 1, 2, 1]), None, [0, 1])


def test_the_task_vector_is_one_hot_over_the_training_tasks_and_zero_for_an_unseen_task():
    step = TaskOneHotProcessorStep(["a", "b", "c"])
    observation = {"observation.state": torch.zeros(3, 2)}
    out = step({"observation": observation, "complementary_data": {"task": ["c", "a", "unseen"]}})
    assert out["observation"][TASK_FEATURE].tolist() == [[0, 0, 1], [1, 0, 0], [0, 0, 0]]
    assert torch.equal(out["observation"][TASK_FEATURE], task_one_hot(torch.tensor([2, 0, -1]), 3))
    untouched = {"observation": observation, "complementary_data": {}}
    assert step(untouched) is untouched


def tiny_act_policy(suite, n_action_steps: int = 3, student: list[str] = TINY_ACT):
    """A tiny untrained ACT (or ``student``) policy of the toy suite, with identity normalisation."""
    options = parse_options(
        RunConfig, ["--suite.name=toy", *student, f"--policy.n_action_steps={n_action_steps}"], "t"
    )
    spec = lerobot_student_config(options.policy, suite.features, suite.task_names, task_dropout=0.0)
    from lerobot_mtdagger.students.lerobot import make_lerobot_processors, make_lerobot_student

    torch.manual_seed(0)
    policy = make_lerobot_student(spec)
    stats = {
        key: {"mean": np.zeros(shape), "std": np.ones(shape), "min": -np.ones(shape), "max": np.ones(shape)}
        for key, shape in (
            ("observation.state", suite.features["observation.state"]["shape"]),
            ("action", (2,)),
        )
    }
    return policy, *make_lerobot_processors(spec, stats)


def test_each_running_episode_keeps_its_own_action_queue(suite):
    """Two episodes started at different steps, batched, act as each would alone with LeRobot's own loop."""
    policy, preprocessor, postprocessor = tiny_act_policy(suite)
    runner = ChunkRunner(policy, preprocessor, postprocessor)
    rng = np.random.default_rng(0)
    dim = suite.features["observation.state"]["shape"][0]
    states = {lane: rng.normal(size=(8, dim)).astype(np.float32) for lane in (0, 1)}
    tasks = {0: "toy-left", 1: "toy-up-windy"}
    offset = 2  # lane 1 starts two steps after lane 0
    batched = {0: [], 1: []}
    for step in range(8 + offset):
        lanes = [lane for lane in (0, 1) if 0 <= step - offset * lane < 8]
        rows = [{"observation.state": states[lane][step - offset * lane]} for lane in lanes]
        starts = [step - offset * lane == 0 for lane in lanes]
        actions = runner(rows, [tasks[lane] for lane in lanes], lanes=lanes, starts=starts)
        for lane, action in zip(lanes, actions, strict=True):
            batched[lane].append(action)
    for lane in (0, 1):
        policy.reset()
        alone = []
        for state in states[lane]:
            batch = preprocessor({"observation.state": torch.from_numpy(state)[None], "task": tasks[lane]})
            with torch.inference_mode():
                alone.append(postprocessor(policy.select_action(batch))[0].numpy())
        np.testing.assert_allclose(np.stack(batched[lane]), np.stack(alone), atol=1e-5)


def test_a_diffusion_episode_sees_its_own_observation_history_as_lerobot_gives_it(suite):
    """With ``n_obs_steps=2`` the runner hands Diffusion each episode's history (the first observation
    repeated at the start), as LeRobot's own ``select_action`` loop does; the noise is seeded alike."""
    policy, preprocessor, postprocessor = tiny_act_policy(suite, n_action_steps=2, student=TINY_DIFFUSION)
    assert policy.config.n_obs_steps == 2
    runner = get_student("diffusion").make_runner(policy, preprocessor, postprocessor)
    states = np.random.default_rng(1).normal(size=(7, suite.features["observation.state"]["shape"][0]))
    states = states.astype(np.float32)
    batched = []
    for step, state in enumerate(states):
        torch.manual_seed(step)
        batched.append(runner([{"observation.state": state}], ["toy-left"], lanes=[3], starts=[step == 0])[0])
    policy.reset()
    alone = []
    for step, state in enumerate(states):
        torch.manual_seed(step)
        batch = preprocessor({"observation.state": torch.from_numpy(state)[None], "task": "toy-left"})
        with torch.inference_mode():
            alone.append(postprocessor(policy.select_action(batch))[0].numpy())
    np.testing.assert_allclose(np.stack(batched), np.stack(alone), atol=1e-5)


def test_a_new_episode_on_a_lane_restarts_its_queue(suite):
    policy, preprocessor, postprocessor = tiny_act_policy(suite, n_action_steps=4)
    runner = ChunkRunner(policy, preprocessor, postprocessor)
    first = {"observation.state": np.zeros(suite.features["observation.state"]["shape"], np.float32)}
    other = {"observation.state": np.ones_like(first["observation.state"])}
    runner([first], ["toy-left"], lanes=[5], starts=[True])
    restarted = runner([other], ["toy-left"], lanes=[5], starts=[True])
    fresh = ChunkRunner(policy, preprocessor, postprocessor)([other], ["toy-left"])
    np.testing.assert_allclose(restarted, fresh, atol=1e-6)


def test_a_chunking_student_runs_an_evaluation_with_queues_keyed_by_lane(suite):
    policy, preprocessor, postprocessor = tiny_act_policy(suite)
    runner = ChunkRunner(policy, preprocessor, postprocessor)
    with EnvWorkers(suite, 0) as workers:
        result, episodes = evaluate(workers, runner, episodes_per_task=2, seed=0)
    assert len(episodes) == 6 and len(result.success) == 3
    assert set(runner.queues) <= set(range(len(suite.task_names)))  # keyed by rollout lane


def test_rollouts_say_each_rows_lane_and_each_episodes_first_step(suite):
    policy, preprocessor, postprocessor = tiny_act_policy(suite)
    runner = ChunkRunner(policy, preprocessor, postprocessor)
    calls = []

    def spy(observations, tasks, lanes=None, starts=None):
        calls.append((lanes, starts))
        return runner(observations, tasks, lanes=lanes, starts=starts)

    with EnvWorkers(suite, 0) as workers:
        _, episodes = evaluate(workers, _Forward(spy), episodes_per_task=2, seed=0)
    assert calls and all(lanes is not None and starts is not None for lanes, starts in calls)
    assert sum(sum(starts) for _, starts in calls) == len(episodes) == 6  # one first step per episode


class _Forward:
    """A policy object that forwards to ``spy`` and says it tracks episodes."""

    tracks_episodes = True

    def __init__(self, spy):
        self.spy = spy

    def __call__(self, observations, tasks, lanes=None, starts=None):
        return self.spy(observations, tasks, lanes=lanes, starts=starts)


def test_the_per_task_loss_of_a_lerobot_student_is_reproducible(act_run):
    from lerobot_mtdagger.runner.training.normalise import NormalisedData
    from lerobot_mtdagger.runner.training.train import RoundCache

    runner = PolicyRunner.from_pretrained(ExperimentDir(act_run).policy_root(2))
    experiment = ExperimentDir(act_run)
    data = RoundCache().load([experiment.round_root(k) for k in range(3)], runner.input_keys)
    task_names = ["toy-left", "toy-right", "toy-up-windy"]
    normalised = NormalisedData(data, runner.preprocessor, [], task_names)
    ops = LeRobotOps(runner.policy, normalised, task_dropout=0.0, seed=3)
    index = torch.arange(len(data))
    first, counts = ops.task_losses(index, 3)
    again, _ = ops.task_losses(index, 3)
    assert first == again and sum(counts) == len(data)
    assert all(loss is not None and loss > 0 for loss in first)


class CutError(Exception):
    """Stands for the end of a process part-way through a phase."""


def act_phase(act_run: Path, progress: Path | None = None, cut_after: int | None = None):
    """45 steps of the trained ACT student on its run's frames, with task dropout (the seam's generator)."""
    from lerobot_mtdagger.runner.training.normalise import NormalisedData
    from lerobot_mtdagger.runner.training.phase_progress import PhaseProgress
    from lerobot_mtdagger.runner.training.steps import StepOptions, train_phase
    from lerobot_mtdagger.runner.training.train import RoundCache

    experiment = ExperimentDir(act_run)
    runner = PolicyRunner.from_pretrained(experiment.policy_root(2))
    data = RoundCache().load([experiment.round_root(k) for k in range(3)], runner.input_keys)
    normalised = NormalisedData(data, runner.preprocessor, [], ["toy-left", "toy-right", "toy-up-windy"])
    options = StepOptions(steps=45, batch_size=8, lr=1e-3, seed=0, log_interval=10, task_dropout=0.5)
    if progress is not None:
        options = dataclasses.replace(options, progress=PhaseProgress(progress, {"round": 2}, 1e-9))

    def on_step(done: int, _loss: float) -> None:
        if cut_after is not None and done >= cut_after:
            raise CutError

    torch.manual_seed(0)
    index = torch.arange(len(data))
    result = train_phase(runner.policy, normalised, index, index[::40], options, on_step)
    return runner.policy.state_dict(), result


def test_a_lerobot_students_phase_cut_part_way_resumes_to_the_uninterrupted_phase(act_run, tmp_path):
    """ACT draws from the global random state (dropout, its VAE) and the seam's own (task dropout)."""
    reference_weights, reference = act_phase(act_run)
    progress = tmp_path / "round-002.pt"
    with pytest.raises(CutError):
        act_phase(act_run, progress, cut_after=30)
    assert list(torch.load(progress, weights_only=True)["seam_rngs"]) == ["generator"]
    weights, resumed = act_phase(act_run, progress)
    assert resumed.resumed_after_steps == [20]
    assert dataclasses.replace(resumed, resumed_after_steps=[]) == reference
    for name, tensor in reference_weights.items():
        assert torch.equal(tensor, weights[name]), name


# -------------------------------------------------------------------------------------------------
# Options
# -------------------------------------------------------------------------------------------------


def test_policy_options_are_lerobots_own_and_mtdagger_stays_the_default():
    assert set(lerobot_students()) == {"act", "diffusion"}
    default = parse_options(RunConfig, [], "t")
    assert default.student_type == "mtdagger" and "type" not in default.to_dict()["policy"]
    act = parse_options(
        RunConfig, ["--policy.type=act", "--policy.chunk_size=20", "--policy.n_action_steps=5"], "t"
    )
    assert act.student_type == "act" and act.policy.chunk_size == 20
    assert act.policy.batch_size == 256  # the preset's
    assert act.to_dict()["policy"]["type"] == "act"


@pytest.mark.parametrize(
    ("options", "message"),
    [
        (
            ["--policy.type=act", "--suite.name=drawers", "--suite.obs_mode=pointcloud"],
            "cannot read point clouds",
        ),
        (
            ["--policy.type=act", "--policy.temporal_ensemble_coeff=0.01", "--policy.n_action_steps=1"],
            "temporal_ensemble_coeff",
        ),
        (["--policy.type=pi0"], "pi0"),
    ],
)
def test_a_student_the_runner_cannot_train_is_refused_before_anything_runs(options, message):
    with pytest.raises(UserError, match=message):
        parse_options(RunConfig, options, "t")


@pytest.mark.slow
@pytest.mark.parametrize("student", [TINY_ACT, TINY_DIFFUSION], ids=["act", "diffusion"])
def test_a_lerobot_student_runs_on_a_metaworld_state_subset(tmp_path, student):
    root = tmp_path / "run"
    lines = run(
        draccus.parse(
            RunConfig,
            args=[
                "--suite.tasks=[reach-v3,button-press-topdown-v3,push-v3]",
                "--dagger.rounds=1",
                "--training.steps_per_round=40",
                "--rollout.eval_episodes=1",
                "--rollout.max_steps=60",
                "--policy.batch_size=64",
                "--progress=false",
                "--rollout.workers=1",
                f"--output_dir={root}",
                *student,
            ],
        )
    )
    assert len(lines) == 2
    assert verify_experiment(ExperimentDir(root))[2] == []
    runner = PolicyRunner.from_pretrained(ExperimentDir(root).policy_root(1))
    assert isinstance(runner, ChunkRunner) and runner.input_keys == ["observation.state"]


def test_predict_gives_each_row_the_first_action_of_a_fresh_chunk(suite):
    """No queue carries over between calls (LeRobot's select_action would keep one)."""
    policy, preprocessor, postprocessor = tiny_act_policy(suite, n_action_steps=3)
    runner = ChunkRunner(policy, preprocessor, postprocessor)
    state = torch.zeros(2, suite.features["observation.state"]["shape"][0])
    first = runner.predict({"observation.state": state}, ["toy-left", "toy-right"])
    again = runner.predict({"observation.state": state}, ["toy-left", "toy-right"])
    torch.testing.assert_close(first, again)
    fresh = runner([{"observation.state": row.numpy()} for row in state], ["toy-left", "toy-right"])
    np.testing.assert_allclose(first.numpy(), fresh, atol=1e-6)
