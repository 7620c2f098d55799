"""Fast tests on the toy suite (no MuJoCo): the suite itself, collection, the loss split, staging and
commit of rounds, and the whole runner end to end in seconds."""

from __future__ import annotations

import json

import draccus
import numpy as np
import pytest
import torch

from lerobot_mtdagger.datasets.experiment_dir import STAGING_DIR, ExperimentDir
from lerobot_mtdagger.datasets.records import (
    DAGGER_ROUND,
    EXECUTED_ACTION,
    LEARNER_ACTED,
    RoundRecord,
    round_features,
)
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.envs.toy import MAX_EPISODE_STEPS, TOY_TASKS
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.rollout.collect import (
    EpisodeOptions,
    episode_seed,
    run_episodes,
    success_by_task,
)
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.runner.training.round_data import TrainingData
from lerobot_mtdagger.runner.training.splits import LOSS_SAMPLES_PER_TASK, split_frames
from lerobot_mtdagger.scheduler import scheduling_methods
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.seeds import COLLECT_STREAM, EVAL_STREAM
from tests.helpers import kill_9_and_check_workers_end

TASKS = list(TOY_TASKS)


@pytest.fixture(scope="module")
def suite():
    return make_suite("toy")


def zero_learner(observations, tasks):
    """A learner that never moves: it drifts with the wind and never succeeds."""
    return np.zeros((len(observations), 2), dtype=np.float32)


def collect(
    suite, counts, beta, policy=zero_learner, seed=0, max_steps=MAX_EPISODE_STEPS, after=0, workers=0
):
    with EnvWorkers(suite, workers) as env_workers:
        options = EpisodeOptions(
            beta=beta,
            seed=seed,
            round_index=1,
            stream=COLLECT_STREAM,
            record=True,
            max_steps=max_steps,
            steps_after_success=after,
        )
        return run_episodes(env_workers, counts, options, policy=policy)


# ---------------------------------------------------------------------------------------------
# The toy suite
# ---------------------------------------------------------------------------------------------


def test_toy_expert_always_succeeds_and_a_zero_learner_never_does(suite):
    experts = collect(suite, [20, 20, 20], beta=1.0)
    learners = collect(suite, [20, 20, 20], beta=0.0)
    assert success_by_task(experts, 3)[0] == [1.0, 1.0, 1.0]
    assert success_by_task(learners, 3)[0] == [0.0, 0.0, 0.0]
    assert all(e.steps == MAX_EPISODE_STEPS for e in learners), "failures run to truncation"


def test_toy_reset_is_seeded_and_observations_match_the_features(suite):
    env = suite.make_env("toy-left")
    first, info = env.reset(seed=3)
    again, _ = env.reset(seed=3)
    other, _ = env.reset(seed=4)
    np.testing.assert_array_equal(first["observation.state"], again["observation.state"])
    assert not np.array_equal(first["observation.state"], other["observation.state"])
    assert set(first) | {"action"} == set(suite.features)
    assert first["observation.state"].shape == suite.features["observation.state"]["shape"]
    assert info["privileged_state"].shape == (6,)


def test_toy_suite_refuses_visual_modes_and_unknown_tasks():
    with pytest.raises(ValueError, match="state observations only"):
        make_suite("toy", observation=ObservationConfig(obs_mode="rgb"))
    with pytest.raises(ValueError, match="Unknown toy task"):
        make_suite("toy", tasks=["toy-down"])


def test_toy_needs_no_mujoco():
    import subprocess
    import sys

    code = (
        "import sys; import lerobot_mtdagger.envs.toy, lerobot_mtdagger.experts.toy; "
        "from lerobot_mtdagger.envs import make_suite; make_suite('toy').make_env('toy-left').reset(seed=0); "
        "print('mujoco' in sys.modules, 'lerobot_mtdagger.envs.metaworld' in sys.modules)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["False", "False"], "the toy suite loads neither MuJoCo nor MetaWorld"


# ---------------------------------------------------------------------------------------------
# Collection
# ---------------------------------------------------------------------------------------------


def frames_of(episodes, key):
    return np.concatenate([np.stack([np.asarray(f[key]).reshape(-1) for f in e.frames]) for e in episodes])


@pytest.mark.parametrize("beta", [0.0, 0.5, 1.0])
def test_the_stored_label_is_always_the_experts(suite, beta):
    episodes = collect(suite, [2, 2, 2], beta=beta)
    expert = make_expert(suite, "toy-left")
    for episode in episodes:
        for frame in episode.frames:
            # The toy expert is stateless, so it can re-label the stored position after the fact.
            state = np.concatenate([frame["observation.state"], TOY_TASKS[TASKS[episode.task_index]].goal])
            state = np.concatenate([state, TOY_TASKS[TASKS[episode.task_index]].wind]).astype(np.float32)
            np.testing.assert_allclose(frame["action"], expert.act(state), atol=1e-6)
    learner = frames_of(episodes, LEARNER_ACTED).astype(bool).reshape(-1)
    executed, label = frames_of(episodes, EXECUTED_ACTION), frames_of(episodes, "action")
    np.testing.assert_array_equal(executed[~learner], label[~learner])
    np.testing.assert_array_equal(executed[learner], 0.0)  # the zero learner's action
    assert set(frames_of(episodes, DAGGER_ROUND).reshape(-1).tolist()) == {1}
    fraction = learner.mean()
    if beta == 1.0:
        assert fraction == 0.0
    elif beta == 0.0:
        assert fraction == 1.0
    else:
        assert 0.3 < fraction < 0.7, fraction


def test_steps_after_success_and_max_steps_end_episodes(suite):
    at_success = collect(suite, [2, 2, 2], beta=1.0, after=0)
    assert all(e.success and e.steps == len(e.frames) < MAX_EPISODE_STEPS for e in at_success)
    later = collect(suite, [2, 2, 2], beta=1.0, after=3)
    assert [e.steps + 3 for e in at_success] == [e.steps for e in later], "same seeds, 3 more steps"
    capped = collect(suite, [2, 2, 2], beta=0.0, max_steps=7)
    assert all(e.steps == len(e.frames) == 7 and not e.success for e in capped)


def test_collection_is_reproducible_under_its_seed(suite):
    first, again, other = (collect(suite, [2, 2, 2], beta=0.5, seed=s) for s in (0, 0, 1))
    assert [e.seed for e in first] == [e.seed for e in again]
    np.testing.assert_array_equal(frames_of(first, EXECUTED_ACTION), frames_of(again, EXECUTED_ACTION))
    assert [e.seed for e in first] != [e.seed for e in other]


def test_collection_and_evaluation_seeds_never_overlap():
    collection = {
        episode_seed(0, COLLECT_STREAM, r, t, e) for r in range(3) for t in range(3) for e in range(5)
    }
    evaluation = {episode_seed(0, EVAL_STREAM, 0, t, e) for t in range(3) for e in range(5)}
    assert not collection & evaluation and max(collection) < 2**31 <= min(evaluation)


def test_collection_without_a_learner_below_beta_1_is_refused(suite):
    with pytest.raises(ValueError, match="needs a learner policy"):
        collect(suite, [1, 1, 1], beta=0.5, policy=None)


# ---------------------------------------------------------------------------------------------
# Loss split
# ---------------------------------------------------------------------------------------------


def training_data(episodes_per_task: int = 5, frames_per_episode: int = 400) -> TrainingData:
    episode_id = torch.arange(3 * episodes_per_task).repeat_interleave(frames_per_episode)
    size = len(episode_id)
    return TrainingData(
        inputs={"observation.state": torch.zeros(size, 2)},
        action=torch.zeros(size, 2),
        task_index=episode_id // episodes_per_task,
        episode_id=episode_id,
    )


def test_train_split_trains_on_everything_and_measures_a_capped_sample_per_task():
    data = training_data()
    split = split_frames(data, "train", 0.2, seed=0)
    assert len(split.train) == len(data) and len(split.heldout) == 0
    counts = torch.bincount(data.task_index[split.loss], minlength=3).tolist()
    assert counts == [LOSS_SAMPLES_PER_TASK] * 3
    assert torch.equal(split.loss, split_frames(data, "train", 0.2, seed=0).loss)


def test_heldout_split_holds_out_whole_episodes_of_every_task():
    data = training_data(episodes_per_task=6)
    split = split_frames(data, "heldout", 0.2, seed=0)
    assert torch.equal(split.loss, split.heldout)
    assert len(split.train) + len(split.heldout) == len(data)
    held_episodes = set(data.episode_id[split.heldout].tolist())
    assert not held_episodes & set(data.episode_id[split.train].tolist())
    assert sorted(data.task_index[split.heldout].unique().tolist()) == [0, 1, 2]
    assert len(held_episodes) == 3, "20% of the 5 episodes after each task's first = 1 per task"


def test_a_plateau_holds_episodes_out_of_training_and_measures_the_gain_on_training_frames():
    data = training_data(episodes_per_task=6)
    split = split_frames(data, "train", 0.2, seed=0, hold_out=True)
    assert len(split.heldout) == 3 * 400 and len(split.train) == len(data) - 3 * 400
    assert not set(split.loss.tolist()) & set(split.heldout.tolist())
    assert torch.equal(split.heldout, split_frames(data, "heldout", 0.2, seed=0).heldout)


# ---------------------------------------------------------------------------------------------
# Staging and commit
# ---------------------------------------------------------------------------------------------


def minimal_record(round_index: int, counts: list[int]) -> RoundRecord:
    blank = {"p": None, "P": None}
    return RoundRecord(
        task_names=TASKS,
        round=round_index,
        method="uniform",
        beta=1.0,
        seed=0,
        budget=sum(counts),
        temperature=0.5,
        n_min=1,
        episodes_per_task=counts,
        demos_so_far=counts,
        rollout_success=None,
        rollout_episodes=counts,
        expert_success=None,
        learner_steps=0,
        frames=0,
        config={},
        success_rate=None,
        episodes=None,
        gain=None,
        kalman_prior=blank,
        kalman_posterior=blank,
        metric=None,
        score=None,
        probability=None,
        eval_success=None,
        allocation=None,
        scheduler_state=None,
        notes=[],
    )


def test_a_round_is_invisible_until_committed_and_immutable_after(tmp_path, suite):
    experiment = ExperimentDir(tmp_path / "exp")
    experiment.initialise({"seed": 0})
    dataset = experiment.create_round(0, round_features(suite.features), TASKS)
    for episode in collect(suite, [1, 1, 1], beta=1.0):
        for frame in episode.frames:
            dataset.add_frame({**frame, "task": TASKS[episode.task_index]})
        dataset.save_episode()
    assert experiment.committed_rounds() == [], "a staged round is never read"
    experiment.commit_round(0, dataset, minimal_record(0, [1, 1, 1]))
    assert experiment.committed_rounds() == [0]
    record = experiment.read_round_record(0)
    assert record.committed and record.episodes_per_task == [1, 1, 1]
    with pytest.raises(FileExistsError, match="immutable"):
        experiment.commit_round(0, dataset, minimal_record(0, [1, 1, 1]))
    staged = experiment.create_round(1, round_features(suite.features), TASKS)
    assert (experiment.rounds / STAGING_DIR / "round-001").exists() and staged is not None
    experiment.clear_staging()
    assert not (experiment.rounds / STAGING_DIR).exists() and experiment.committed_rounds() == [0]


def test_a_record_missing_a_field_is_a_clear_error():
    stored = minimal_record(0, [1, 1, 1]).to_dict()
    del stored["demos_so_far"]
    with pytest.raises(ValueError, match=r"missing the field\(s\) \['demos_so_far'\]"):
        RoundRecord.from_dict(stored)


# ---------------------------------------------------------------------------------------------
# The runner end to end
# ---------------------------------------------------------------------------------------------

TOY_RUN = [
    "--suite.name=toy",
    "--dagger.rounds=2",
    "--dagger.initial_demos=1",
    "--dagger.budget_per_task=2",
    "--training.steps_per_round=30",
    "--rollout.eval_episodes=2",
    "--rollout.max_steps=40",
    "--policy.batch_size=32",
    "--policy.state_hidden_dims=[32]",
    "--policy.head_hidden_dims=[32]",
    "--progress=false",
]


def toy_config(output_dir, *extra: str) -> RunConfig:
    return draccus.parse(RunConfig, args=[*TOY_RUN, f"--output_dir={output_dir}", *extra])


@pytest.mark.parametrize("method", scheduling_methods())
def test_every_method_runs_end_to_end_and_verifies(tmp_path, method):
    lines = run(toy_config(tmp_path / method, f"--scheduler.type={method}"))
    experiment = ExperimentDir(tmp_path / method)
    assert len(lines) == 3 and experiment.committed_phases() == [0, 1, 2]
    assert verify_experiment(experiment) == (3, 3, [])
    records = [experiment.read_round_record(k) for k in range(3)]
    assert [r.method for r in records] == [method] * 3
    assert [sum(r.episodes_per_task) for r in records] == [3, 6, 6]
    assert records[2].allocation["method"] == method


def test_the_learning_rate_schedule_reaches_the_training_phase(tmp_path):
    from lerobot_mtdagger.policies import MTDAggerPolicy

    weights = {}
    for schedule in ("constant", "cosine"):
        root = tmp_path / schedule
        run(toy_config(root, "--dagger.rounds=0", f"--training.lr_schedule={schedule}"))
        policy = MTDAggerPolicy.from_pretrained(str(ExperimentDir(root).policy_root(0)))
        weights[schedule] = policy.state_dict()
        assert json.loads((root / "config.json").read_text())["training"]["lr_schedule"] == schedule
    assert any(not torch.equal(t, weights["cosine"][n]) for n, t in weights["constant"].items())


def _bc_weights(root):
    from lerobot_mtdagger.policies import MTDAggerPolicy

    return MTDAggerPolicy.from_pretrained(str(ExperimentDir(root).policy_root(0))).state_dict()


def test_a_training_seed_retrains_on_the_same_data_and_the_run_seed_is_its_default(tmp_path):
    """``--training.seed`` changes the training draws alone: another training on the very same data."""
    for name, extra in (("default", ()), ("same", ("--training.seed=0",)), ("other", ("--training.seed=1",))):
        run(toy_config(tmp_path / name, "--mode=bc", "--seed=0", *extra))
    records = {
        name: ExperimentDir(tmp_path / name).read_round_record(0) for name in ("default", "same", "other")
    }
    assert records["other"].files == records["default"].files  # the same frames, byte for byte
    weights = {name: _bc_weights(tmp_path / name) for name in records}
    for name, tensor in weights["default"].items():
        torch.testing.assert_close(tensor, weights["same"][name], rtol=0, atol=0)  # unset = --seed
    assert any(not torch.equal(t, weights["other"][n]) for n, t in weights["default"].items())


def test_a_phase_records_the_environment_its_arithmetic_depends_on(tmp_path):
    """Two trainings of the same data differ in the last bits on another CPU or torch: say which."""
    import importlib.metadata

    run(toy_config(tmp_path / "bc", "--mode=bc"))
    stored = json.loads((ExperimentDir(tmp_path / "bc").policy_root(0) / "training.json").read_text())
    environment = stored["environment"]
    assert environment["packages"]["torch"] == importlib.metadata.version("torch")
    assert environment["packages"]["lerobot"] == importlib.metadata.version("lerobot")
    assert environment["cpu_capability"] == torch.backends.cpu.get_cpu_capability()
    assert environment["device"] == "cpu" and environment["device_name"] is None
    assert environment["torch_threads"] >= 1 and environment["cpu"]
    assert ExperimentDir(tmp_path / "bc").read_phase_record(0).environment == environment


def test_a_training_seed_must_be_kept_on_resume_and_be_positive(tmp_path, capsys):
    from lerobot_mtdagger.cli import main

    run(toy_config(tmp_path / "bc", "--mode=bc", "--training.seed=3"))
    with pytest.raises(UserError, match=r"training.seed"):
        run(toy_config(tmp_path / "bc", "--mode=bc", "--resume=true"))
    assert main(["run", *TOY_RUN, "--training.seed=-1", f"--output_dir={tmp_path / 'other'}"]) == 2
    assert "training.seed must be >= 0" in capsys.readouterr().err
    assert not (tmp_path / "other").exists()


def test_bc_mode_runs_one_round_with_the_same_budget_and_compute(tmp_path):
    lines = run(toy_config(tmp_path / "bc", "--mode=bc"))
    experiment = ExperimentDir(tmp_path / "bc")
    record = experiment.read_round_record(0)
    assert len(lines) == 1 and experiment.committed_rounds() == [0]
    assert record.method == "bc" and record.episodes_per_task == [1 + 2 * 2] * 3
    assert experiment.read_phase_record(0).steps == 3 * 30
    assert json.loads((tmp_path / "bc" / "config.json").read_text())["mode"] == "bc"


def test_a_run_cut_after_a_phase_resumes_to_the_same_rounds_and_weights(tmp_path):
    import shutil

    from lerobot_mtdagger.policies import MTDAggerPolicy

    reference = tmp_path / "reference"
    run(toy_config(reference))
    cut = tmp_path / "cut"
    shutil.copytree(reference, cut)
    shutil.rmtree(cut / "rounds" / "round-002")  # as if killed right after phase 1 was committed
    shutil.rmtree(cut / "policies" / "round-002")
    run(toy_config(cut, "--resume=true"))
    records = [[ExperimentDir(root).read_round_record(k) for k in range(3)] for root in (reference, cut)]
    strip = [[{**r.to_dict(), "config": None} for r in rs] for rs in records]  # config holds output_dir
    assert strip[0] == strip[1]
    weights = [
        MTDAggerPolicy.from_pretrained(str(ExperimentDir(r).policy_root(2))).state_dict()
        for r in (reference, cut)
    ]
    for name, tensor in weights[0].items():
        torch.testing.assert_close(tensor, weights[1][name], rtol=0, atol=0)


KILLED_RUN = ["--rollout.workers=2", "--training.steps_per_round=150"]  # a phase long enough to hit


def test_kill_9_during_training_then_resume_equals_the_uninterrupted_run(tmp_path):
    """A toy run with two env workers killed (SIGKILL) in phase 1: its workers end with it, and
    ``--resume=true`` gives the uninterrupted run's rounds and weights (MetaWorld: the slow set)."""
    import subprocess
    import sys
    import time
    from pathlib import Path

    from lerobot_mtdagger.policies import MTDAggerPolicy

    reference, killed = tmp_path / "reference", tmp_path / "killed"
    run(toy_config(reference, *KILLED_RUN))
    command = [str(Path(sys.executable).parent / "lerobot-mtdagger"), "run", *TOY_RUN, *KILLED_RUN]
    process = subprocess.Popen(
        [*command, f"--output_dir={killed}"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.time() + 120
    while not (killed / "policies" / ".staging" / "round-001").exists() and time.time() < deadline:
        assert process.poll() is None, "the run ended before phase 1 started"
        time.sleep(0.02)
    kill_9_and_check_workers_end(process, workers=2)
    assert ExperimentDir(killed).committed_phases() == [0], "the kill should have cut phase 1"
    subprocess.run([*command, f"--output_dir={killed}", "--resume=true"], check=True, capture_output=True)
    assert verify_experiment(ExperimentDir(killed)) == (3, 3, [])
    records = [[ExperimentDir(root).read_round_record(k) for k in range(3)] for root in (reference, killed)]
    strip = [[{**r.to_dict(), "config": None} for r in rs] for rs in records]  # config holds output_dir
    assert strip[0] == strip[1]
    for k in range(3):
        weights = [
            MTDAggerPolicy.from_pretrained(str(ExperimentDir(r).policy_root(k))).state_dict()
            for r in (reference, killed)
        ]
        for name, tensor in weights[0].items():
            torch.testing.assert_close(tensor, weights[1][name], rtol=0, atol=0)


def test_a_dagger_run_resumed_with_more_rounds_equals_one_started_with_them(tmp_path):
    from lerobot_mtdagger.policies import MTDAggerPolicy

    reference, extended = tmp_path / "reference", tmp_path / "extended"
    run(toy_config(reference))  # 2 rounds from the start
    run(toy_config(extended, "--dagger.rounds=1"))
    assert len(run(toy_config(extended, "--dagger.rounds=2", "--resume=true"))) == 3
    assert json.loads((extended / "config.json").read_text())["dagger"]["rounds"] == 2
    experiments = [ExperimentDir(reference), ExperimentDir(extended)]
    records = [[{**e.read_round_record(k).to_dict(), "config": None} for k in range(3)] for e in experiments]
    assert records[0] == records[1]  # the same allocations, from the same measured success and gain
    phases = [[e.read_phase_record(k) for k in range(3)] for e in experiments]
    assert [(p.eval, p.gain, p.loss_end) for p in phases[0]] == [
        (p.eval, p.gain, p.loss_end) for p in phases[1]
    ]
    weights = [MTDAggerPolicy.from_pretrained(str(e.policy_root(2))).state_dict() for e in experiments]
    for name, tensor in weights[0].items():
        torch.testing.assert_close(tensor, weights[1][name], rtol=0, atol=0)
    assert verify_experiment(experiments[1]) == (3, 3, [])


def test_rounds_may_only_grow_and_only_for_dagger(tmp_path):
    dagger, bc = tmp_path / "dagger", tmp_path / "bc"
    run(toy_config(dagger, "--dagger.rounds=1"))
    run(toy_config(bc, "--mode=bc", "--dagger.rounds=1"))
    hint = r"\(--dagger.rounds may only grow, and only for a DAgger run"
    with pytest.raises(UserError, match=r"rounds: 1 -> 0\) " + hint):
        run(toy_config(dagger, "--dagger.rounds=0", "--resume=true"))
    with pytest.raises(UserError, match=r"rounds: 1 -> 2\) " + hint):
        run(toy_config(bc, "--mode=bc", "--dagger.rounds=2", "--resume=true"))
    assert json.loads((bc / "config.json").read_text())["dagger"]["rounds"] == 1
    assert ExperimentDir(bc).committed_rounds() == [0] and ExperimentDir(dagger).committed_phases() == [0, 1]


def test_nan_loss_is_an_error_and_committed_rounds_survive(tmp_path, monkeypatch):
    import math

    from lerobot_mtdagger.policies import MTDAggerPolicy

    def nan_forward(self, batch):
        loss = self.predict(batch).sum() * math.nan
        return loss, {}

    monkeypatch.setattr(MTDAggerPolicy, "forward", nan_forward)
    with pytest.raises(FloatingPointError, match="Training loss became nan"):
        run(toy_config(tmp_path / "exp", "--dagger.rounds=1"))
    experiment = ExperimentDir(tmp_path / "exp")
    assert experiment.committed_rounds() == [0]
    assert experiment.committed_phases() == []
    monkeypatch.undo()
    run(toy_config(tmp_path / "exp", "--dagger.rounds=1", "--resume=true"))
    assert experiment.committed_phases() == [0, 1]


def test_rounds_carry_provenance_in_lerobots_column_names(tmp_path):
    """intervention, next.reward / next.success / next.done per frame; success per episode."""
    import pyarrow.parquet as pq
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_mtdagger.datasets.records import INTERVENTION, NEXT_DONE, NEXT_REWARD, NEXT_SUCCESS

    run(toy_config(tmp_path / "run", "--dagger.rounds=1"))
    experiment = ExperimentDir(tmp_path / "run")
    for k in (0, 1):
        root = experiment.round_root(k)
        frames = pq.read_table(sorted((root / "data").glob("*/*.parquet"))).to_pandas()
        episodes = pq.read_table(sorted((root / "meta" / "episodes").glob("*/*.parquet"))).to_pandas()
        assert (frames[INTERVENTION] == ~frames[LEARNER_ACTED]).all()
        assert frames[INTERVENTION].all() if k == 0 else not frames[INTERVENTION].all()
        last = frames.groupby("episode_index")["frame_index"].transform("max") == frames["frame_index"]
        assert (frames[NEXT_DONE] == last).all()
        reached = frames.groupby("episode_index")[NEXT_SUCCESS].any()
        assert (
            episodes.set_index("episode_index")["success"].sort_index().tolist()
            == reached.sort_index().tolist()
        )
        assert np.isfinite(frames[NEXT_REWARD]).all()
        assert LeRobotDataset("local/round", root=root)[0][NEXT_SUCCESS].dtype == torch.bool
    record = experiment.read_round_record(0)
    assert sum(record.expert_success[i] * record.rollout_episodes[i] for i in range(3)) == pytest.approx(
        episodes_success_total(experiment.round_root(0))
    )
    assert verify_experiment(experiment) == (2, 2, [])


def episodes_success_total(root) -> int:
    import pyarrow.parquet as pq

    return int(
        pq.read_table(sorted((root / "meta" / "episodes").glob("*/*.parquet")))["success"].to_numpy().sum()
    )


def test_an_experiment_started_without_provenance_columns_keeps_its_schema(tmp_path, suite):
    from lerobot_mtdagger.datasets.records import INTERVENTION, StepOutcome, dagger_columns

    experiment = ExperimentDir(tmp_path / "old")
    old_features = round_features(suite.features, provenance=False)
    frame = {
        "observation.state": np.zeros(suite.features["observation.state"]["shape"], np.float32),
        "action": np.zeros(2, np.float32),
        **dagger_columns(np.zeros(2), False, 0, StepOutcome(0.0, False, True)),
    }
    experiment.initialise({"seed": 0})
    staged = experiment.write_round(0, old_features, TASKS, [(TASKS[0], [frame])])  # provenance dropped
    assert INTERVENTION not in staged.features
    experiment.commit_round(0, staged, minimal_record(0, [1, 0, 0]))
    assert INTERVENTION not in experiment.round_features(suite.features)
    assert INTERVENTION in ExperimentDir(tmp_path / "new").round_features(suite.features)


def test_eval_phases_evaluates_only_the_phases_named_and_allocates_as_before(tmp_path, capsys):
    from lerobot_mtdagger.cli import main

    lines = run(toy_config(tmp_path / "some", "--rollout.eval_phases=[0,2]"))
    every = run(toy_config(tmp_path / "every"))
    some, all_phases = ExperimentDir(tmp_path / "some"), ExperimentDir(tmp_path / "every")
    evaluated = [some.read_phase_record(k).eval is not None for k in range(3)]
    assert evaluated == [True, False, True] and "eval success n/a" in lines[1]
    assert [some.read_round_record(k).episodes_per_task for k in range(3)] == [
        all_phases.read_round_record(k).episodes_per_task for k in range(3)
    ]
    assert every[2].split("|")[1] == lines[2].split("|")[1]  # demos per task
    assert verify_experiment(some) == (3, 3, [])
    # Recorded with the run: a resume with other phases is refused; report reads the evaluated ones.
    with pytest.raises(UserError, match=r"rollout.eval_phases"):
        run(toy_config(tmp_path / "some", "--rollout.eval_phases=[2]", "--resume=true"))
    assert (
        main(["report", f"--experiments=[{tmp_path / 'some'}]", f"--output_dir={tmp_path / 'report'}"]) == 0
    )
    table = capsys.readouterr().out
    assert "| need | 0 |" in table and "| need | 2 |" in table and "| need | 1 |" not in table
    assert main(["run", *TOY_RUN, "--rollout.eval_phases=[-1]", f"--output_dir={tmp_path / 'bad'}"]) == 2
    assert "rollout.eval_phases must list phase indices >= 0" in capsys.readouterr().err
    assert not (tmp_path / "bad").exists()
