"""The DAgger protocol: what task need and performance gain measure, and how phases train.

Each test pins down one defect of the earlier protocol (a biased measurement or an unfair
comparison) and fails on it:

1. task need credited the learner with successes the expert made (per-step mixing at beta 0.5);
2. the first performance-gain allocation ranked tasks by the scale of their actions;
3. held-out episodes were redrawn every phase, so a warm-started policy had trained on them;
4. DAgger rollouts were cut at 200 steps while evaluation runs to the env's 500;
5. normalisation statistics changed under a warm-started policy;
6. BC and DAgger phases were trained by different rules.
"""

from __future__ import annotations

import dataclasses
import json
from pathlib import Path

import draccus
import numpy as np
import pytest
import torch

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.option_groups import RolloutConfig, TrainingConfig
from lerobot_mtdagger.runner.rollout.collect import (
    EpisodeOptions,
    learner_success_by_task,
    run_episodes,
    success_by_task,
)
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.runner.rollout.mixing import expert_episode_coin
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.runner.training.normalise import NormalisedData, compute_stats
from lerobot_mtdagger.runner.training.round_data import EPISODE_ID_STRIDE, TrainingData
from lerobot_mtdagger.runner.training.splits import heldout_episodes, split_frames
from lerobot_mtdagger.runner.training.steps import batch_sampler
from lerobot_mtdagger.runner.training.task_loss import performance_gain
from lerobot_mtdagger.students.mtdagger import build_processors, per_task_loss, per_task_loss_of
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.seeds import BETA_STREAM, COLLECT_STREAM
from tests.test_toy import TOY_RUN
from tests.test_train import normalised, small_policy, synthetic_data

REACH_PUSH_PICK = ["reach-v3", "push-v3", "pick-place-v3"]


def zero_actions(observations, tasks):
    return np.zeros((len(observations), 4), dtype=np.float32)


@pytest.fixture(scope="module")
def metaworld_rollouts():
    """A zero-action learner on reach, push and pick-place at beta 0.5, both mixings (4 episodes each)."""
    suite = make_suite("metaworld-mt10", tasks=REACH_PUSH_PICK)
    rollouts = {}
    with EnvWorkers(suite, 0) as workers:
        for mixing in ("step", "episode"):
            options = EpisodeOptions(
                beta=0.5,
                seed=100,
                round_index=1,
                stream=COLLECT_STREAM,
                record=False,
                max_steps=None,
                steps_after_success=0,
                mixing=mixing,
            )
            rollouts[mixing] = run_episodes(workers, [4, 4, 4], options, policy=zero_actions)
    return rollouts


def test_a_zero_action_learner_measures_zero_task_success(metaworld_rollouts):
    """Defect 1: the measurement that feeds task need counts the learner's episodes only."""
    mixed, _ = success_by_task(metaworld_rollouts["step"], 3)
    assert mixed[0] == 1.0, "under step mixing the expert reaches for the learner"
    assert learner_success_by_task(metaworld_rollouts["step"], 3) == ([None] * 3, [0, 0, 0]), (
        "step mixing at beta 0.5 leaves no learner-only episode: nothing is credited"
    )
    rates, counts = learner_success_by_task(metaworld_rollouts["episode"], 3)
    assert rates == [0.0, 0.0, 0.0] and counts == [2, 2, 2]
    experts = [e for e in metaworld_rollouts["episode"] if e.learner_steps == 0]
    assert len(experts) == 6 and all(e.success for e in experts if e.task_index == 0)


def test_default_rollouts_run_to_the_evaluation_horizon(metaworld_rollouts):
    """Defect 4: a learner rollout is not cut before evaluation's horizon (the env's own, 500)."""
    assert RunConfig().rollout.max_steps is None
    learner = [e for e in metaworld_rollouts["episode"] if e.learner_only]
    assert {e.steps for e in learner} == {500}


def expert_steps_to_success(suite, task: str, reset_seed: int) -> int | None:
    """The expert's own steps to its first success from ``reset_seed`` (fresh env and expert)."""
    from lerobot_mtdagger.experts import make_expert

    env, expert = suite.make_env(task), make_expert(suite, task)
    expert.reset()
    _, info = env.reset(seed=reset_seed)
    for step in range(1, 501):
        _, _, terminated, truncated, info = env.step(expert.act(info["privileged_state"]))
        if info["success"]:
            return step
        if terminated or truncated:
            break
    return None


def test_rollouts_can_end_at_a_multiple_of_the_experts_length_on_the_same_seed():
    """``rollout_expert_multiple``: a failing learner is cut at ceil(m * the expert's steps to success)."""
    suite = make_suite("metaworld-mt10", tasks=REACH_PUSH_PICK)
    with EnvWorkers(suite, 0) as workers:
        options = EpisodeOptions(
            beta=0.5,
            seed=100,
            round_index=1,
            stream=COLLECT_STREAM,
            record=True,
            max_steps=None,
            steps_after_success=10,
            mixing="episode",
        )
        cutting = dataclasses.replace(options, expert_multiple=1.5)
        episodes = run_episodes(workers, [2, 2, 2], cutting, policy=zero_actions)
        uncut = run_episodes(workers, [2, 2, 2], options, policy=zero_actions)
    for cut, whole in zip(episodes, uncut, strict=True):  # the expert's trial run leaves no trace
        states = [frame["observation.state"] for frame in cut.frames]
        assert np.array_equal(states, [frame["observation.state"] for frame in whole.frames[: len(states)]])
    learner = [e for e in episodes if e.learner_only]
    assert len(learner) == 3  # one learner episode per task at beta 0.5
    for episode in learner:
        expert_steps = expert_steps_to_success(suite, REACH_PUSH_PICK[episode.task_index], episode.seed)
        assert expert_steps is not None and expert_steps < 200
        assert episode.steps == len(episode.frames) == int(np.ceil(1.5 * expert_steps)), episode
    # The expert's own episodes are not cut: they end 10 steps after success as before.
    experts = [e for e in episodes if e.learner_steps == 0]
    for episode in experts:
        expert_steps = expert_steps_to_success(suite, REACH_PUSH_PICK[episode.task_index], episode.seed)
        assert episode.success and episode.steps == expert_steps + 10
    with pytest.raises(ValueError, match="rollout.expert_multiple must be > 0"):
        RunConfig(rollout=RolloutConfig(expert_multiple=0.0))


def test_episode_mixing_gives_each_task_its_share_of_expert_episodes():
    for beta in (0.25, 0.5, 0.75):
        for task in range(5):
            coins = [expert_episode_coin((7, BETA_STREAM, 1, task, e), beta) for e in range(12)]
            for n in range(1, 13):
                assert np.floor(beta * n) <= sum(coins[:n]) <= np.ceil(beta * n)
    assert not any(expert_episode_coin((0, BETA_STREAM, 1, 0, e), 0.0) for e in range(10))
    assert all(expert_episode_coin((0, BETA_STREAM, 1, 0, e), 1.0) for e in range(10))


@pytest.mark.parametrize("expert_multiple", [None, 2.0])
def test_episode_mixing_does_not_depend_on_the_worker_count(expert_multiple):
    suite = make_suite("toy")

    def collect(workers: int):
        with EnvWorkers(suite, workers) as env_workers:
            options = EpisodeOptions(
                beta=0.5,
                seed=3,
                round_index=1,
                stream=COLLECT_STREAM,
                record=True,
                max_steps=40,
                steps_after_success=0,
                mixing="episode",
                expert_multiple=expert_multiple,
            )
            policy = lambda obs, tasks: np.full((len(obs), 2), 0.1, dtype=np.float32)  # noqa: E731
            episodes = run_episodes(env_workers, [3, 2, 4], options, policy=policy)
        return [(e.task_index, e.episode, e.steps, e.learner_steps, e.success) for e in episodes]

    assert collect(0) == collect(2)


def test_heldout_episodes_stay_held_out_when_rounds_are_added():
    """Defect 3: an episode held out in one phase is held out in every later phase."""

    def round_data(position: int, episodes_per_task: int) -> TrainingData:
        episode = torch.arange(3 * episodes_per_task).repeat_interleave(20)
        return TrainingData(
            inputs={"observation.state": torch.zeros(len(episode), 2)},
            action=torch.zeros(len(episode), 2),
            task_index=episode % 3,
            episode_id=episode + position * EPISODE_ID_STRIDE,
        )

    round0, round1 = round_data(0, 6), round_data(1, 4)
    held0 = split_frames(round0, "heldout", 0.2, seed=5).heldout
    both = TrainingData.concat([round0, round1])
    split_both = split_frames(both, "heldout", 0.2, seed=5)
    before = set(round0.episode_id[held0].tolist())
    after = set(both.episode_id[split_both.heldout].tolist())
    assert before and before == {e for e in after if e < EPISODE_ID_STRIDE}
    assert not before & set(both.episode_id[split_both.train].tolist())
    assert {e for e in after if e >= EPISODE_ID_STRIDE}, "the new round holds out episodes too"


def rounds_of(episodes_per_task: list[int]) -> TrainingData:
    """Rounds of 3 tasks, ``episodes_per_task[k]`` episodes each in round k (task = episode % 3)."""
    parts = []
    for position, count in enumerate(episodes_per_task):
        episode = torch.arange(3 * count).repeat_interleave(4)
        parts.append(
            TrainingData(
                inputs={"observation.state": torch.zeros(len(episode), 2)},
                action=torch.zeros(len(episode), 2),
                task_index=episode % 3,
                episode_id=episode + position * EPISODE_ID_STRIDE,
            )
        )
    return TrainingData.concat(parts)


def held_per_task(data: TrainingData, fraction: float, seed: int) -> list[int]:
    held = torch.from_numpy(np.isin(data.episode_id.numpy(), heldout_episodes(data, fraction, seed)))
    return [len(torch.unique(data.episode_id[held & (data.task_index == t)])) for t in range(3)]


@pytest.mark.parametrize("fraction", [0.2, 0.5])
def test_bc_and_dagger_hold_out_the_same_share_of_each_tasks_episodes(fraction):
    """12 episodes per task in one round (BC) or in four rounds of 3 (DAgger): the same share."""
    for seed in range(5):
        bc = held_per_task(rounds_of([12]), fraction, seed)
        dagger = held_per_task(rounds_of([3, 3, 3, 3]), fraction, seed)
        assert bc == dagger
        assert all(np.floor(fraction * 11) <= n <= np.ceil(fraction * 11) for n in bc), bc


def test_a_tasks_first_episode_is_never_held_out():
    assert held_per_task(rounds_of([1]), 0.9, seed=0) == [0, 0, 0]
    for seed in range(5):
        held = set(heldout_episodes(rounds_of([2]), 0.9, seed))
        assert not held & {0, 1, 2}, "episodes 0-2 are each task's first"
        assert held, "at 0.9 the second episodes are held out"


def test_the_previous_policy_is_measured_in_the_current_normalisation():
    """Defects 2 and 5: the gain compares two policies on the same frames, in one normalisation."""
    data = synthetic_data()
    policy = small_policy()
    stats = compute_stats(data, [])
    runner = PolicyRunner(policy, *build_processors(policy.config, stats))
    same = normalised(data, policy)
    index = torch.arange(0, len(data), 2)
    own, _ = per_task_loss(policy, same, index, 3)
    assert per_task_loss_of(runner.predict, same, index, 3) == pytest.approx(own, rel=1e-5)
    wider = {k: dict(v) for k, v in stats.items()}
    wider["action"]["std"] = stats["action"]["std"] * 2
    other = NormalisedData(data, build_processors(policy.config, wider)[0], [], policy.config.task_names)
    scaled = per_task_loss_of(runner.predict, other, index, 3)
    assert scaled == pytest.approx([value / 4 for value in own], rel=1e-4)
    assert performance_gain([1.0, 0.5, None], [0.25, 0.75, 0.1]) == [0.75, 0.0, 0.0]


def test_balanced_sampling_gives_every_task_the_same_share():
    task_index = torch.cat([torch.zeros(900, dtype=torch.long), torch.ones(100, dtype=torch.long)])
    train_index = torch.arange(1000)
    generator = torch.Generator().manual_seed(0)
    balanced = batch_sampler(train_index, task_index, "balanced", generator)((50, 200))
    uniform = batch_sampler(train_index, task_index, "uniform", generator)((50, 200))
    assert task_index[balanced].float().mean() == pytest.approx(0.5, abs=0.02)
    assert task_index[uniform].float().mean() == pytest.approx(0.1, abs=0.02)
    with pytest.raises(ValueError, match="sampling"):
        batch_sampler(train_index, task_index, "by-length", generator)


def phase_steps(*args: str) -> int:
    return draccus.parse(RunConfig, args=list(args)).phase_steps(12_000)


def test_bc_and_dagger_phases_train_by_one_rule():
    """Defect 6: at every budget BC trains like a DAgger phase."""
    assert (
        phase_steps("--mode=bc", "--training.warm_start=false")
        == phase_steps("--training.warm_start=false")
        == 1500
    )
    assert phase_steps("--mode=bc") == 4 * 1500, "warm start: BC gets the final DAgger policy's steps in all"
    epochs = ["--training.steps_rule=epochs", "--training.epochs=10"]
    assert phase_steps("--mode=bc", *epochs) == phase_steps(*epochs) == int(np.ceil(10 * 12_000 / 256))
    plateau = ["--training.steps_rule=plateau", "--training.plateau_max_steps=9000"]
    assert phase_steps("--mode=bc", *plateau) == phase_steps(*plateau) == 9000, "the cap"
    with pytest.raises(ValueError, match="training.steps_rule"):
        RunConfig(training=TrainingConfig(steps_rule="until-bored"))
    with pytest.raises(ValueError, match="training.plateau_patience must be > 0"):
        RunConfig(training=TrainingConfig(steps_rule="plateau", plateau_patience=0))


def test_a_plateau_run_stops_each_phase_on_held_out_episodes_and_records_where(tmp_path):
    root = tmp_path / "plateau"
    plateau = [
        "--training.steps_rule=plateau",
        "--training.plateau_every=5",
        "--training.plateau_patience=2",
        "--training.plateau_max_steps=60",
    ]
    config = draccus.parse(
        RunConfig,
        args=[
            *TOY_RUN,
            "--dagger.rounds=1",
            "--dagger.initial_demos=4",
            "--training.heldout_fraction=0.5",
            *plateau,
        ]
        + [f"--output_dir={root}"],
    )
    run(config)
    experiment = ExperimentDir(root)
    for phase in experiment.committed_phases():
        record = json.loads((experiment.policy_root(phase) / "training.json").read_text())
        steps = [step for step, _ in record["heldout_loss"]]
        assert steps[0] == 0 and steps[-1] == record["steps"] <= 60
        assert record["best_step"] in steps
        assert record["steps"] == 60 or len(steps) == steps.index(record["best_step"]) + 1 + 2


def test_a_plateau_run_without_held_out_episodes_is_refused_before_anything_runs(tmp_path):
    root = tmp_path / "plateau"
    config = draccus.parse(
        RunConfig, args=[*TOY_RUN, "--training.steps_rule=plateau", f"--output_dir={root}"]
    )
    with pytest.raises(
        UserError, match="would hold none out.*Raise --training.heldout_fraction or --dagger.initial_demos"
    ):
        run(config)
    assert not root.exists()


def normaliser_stats(policy_root: Path) -> bytes:
    (path,) = policy_root.glob("policy_preprocessor_step_*_normalizer_processor.safetensors")
    return path.read_bytes()


@pytest.mark.parametrize("normalisation", ["fixed", "recompute"])
def test_normalisation_is_fixed_after_round_0_unless_asked(tmp_path, normalisation):
    root = tmp_path / normalisation
    config = draccus.parse(
        RunConfig,
        args=[
            *TOY_RUN,
            "--dagger.rounds=1",
            f"--training.normalisation={normalisation}",
            f"--output_dir={root}",
        ],
    )
    run(config)
    experiment = ExperimentDir(root)
    same = normaliser_stats(experiment.policy_root(0)) == normaliser_stats(experiment.policy_root(1))
    assert same == (normalisation == "fixed")
    phase1 = json.loads((experiment.policy_root(1) / "training.json").read_text())
    assert phase1["loss_previous"] is not None and phase1["gain"] is not None
