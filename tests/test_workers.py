"""Env workers: results never depend on the worker count; a dead or failing worker is a clear error."""

from __future__ import annotations

import os
import signal

import draccus
import numpy as np
import pandas as pd
import pytest

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir
from lerobot_mtdagger.envs import SuiteConfig, make_suite
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.option_groups import RolloutConfig
from lerobot_mtdagger.runner.rollout.collect import EpisodeOptions, run_episodes
from lerobot_mtdagger.runner.rollout.evaluate import evaluate
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers, RemoteWorkerError, WorkerDiedError
from lerobot_mtdagger.utils.seeds import COLLECT_STREAM

from .test_toy import TOY_RUN


@pytest.fixture(scope="module")
def suite():
    return make_suite("toy")


def tilted_learner(observations, tasks):
    """A deterministic learner that succeeds on some episodes and fails on others."""
    state = np.stack([o["observation.state"] for o in observations])
    return np.tanh(state[:, :2] * np.array([[-0.9, 0.4]], dtype=np.float32)).astype(np.float32)


def collect(suite, workers, counts=(4, 1, 6), beta=0.5, policy=tilted_learner):
    with EnvWorkers(suite, workers) as env_workers:
        options = EpisodeOptions(
            beta=beta,
            seed=7,
            round_index=1,
            stream=COLLECT_STREAM,
            record=True,
            max_steps=30,
            steps_after_success=3,
        )
        return run_episodes(env_workers, list(counts), options, policy=policy)


def episode_key(episode):
    frames = [{k: np.asarray(v).tolist() for k, v in frame.items()} for frame in episode.frames]
    return (episode.task_index, episode.episode, episode.seed, episode.success, episode.steps, frames)


@pytest.mark.parametrize("beta", [0.5, 1.0])
def test_collection_is_identical_with_0_1_and_2_workers(suite, beta):
    """beta 1: expert demonstrations, which a worker runs to the end within one message."""
    policy = tilted_learner if beta < 1 else None
    results = {
        workers: [episode_key(e) for e in collect(suite, workers, beta=beta, policy=policy)]
        for workers in (0, 1, 2)
    }
    assert len(results[0]) == 11
    if beta < 1:
        assert {e[3] for e in results[0]} == {True, False}, "the learner should both succeed and fail"
    assert results[1] == results[0]
    assert results[2] == results[0]


def test_evaluation_is_identical_with_0_1_and_2_workers(suite):
    outcomes = {}
    for workers in (0, 1, 2):
        with EnvWorkers(suite, workers) as env_workers:
            result, episodes = evaluate(env_workers, tilted_learner, episodes_per_task=5, seed=3)
        outcomes[workers] = (result.to_dict(), [(e.task_index, e.seed, e.steps, e.success) for e in episodes])
    assert outcomes[1] == outcomes[0] and outcomes[2] == outcomes[0]


def round_frames(root):
    tables = [pd.read_parquet(path) for path in sorted((root / "data").rglob("*.parquet"))]
    return pd.concat(tables, ignore_index=True)


def test_runs_with_1_and_2_workers_write_identical_rounds_and_evaluations(tmp_path):
    experiments = {}
    for workers in (1, 2):
        args = [*TOY_RUN, f"--output_dir={tmp_path / str(workers)}", f"--rollout.workers={workers}"]
        run(draccus.parse(RunConfig, args=args))
        experiments[workers] = ExperimentDir(tmp_path / str(workers))
    for round_index in range(3):
        records = [experiments[w].read_round_record(round_index).to_dict() for w in (1, 2)]
        for record in records:
            record.pop("config")  # holds output_dir and workers
        assert records[0] == records[1]
        frames = [round_frames(experiments[w].round_root(round_index)) for w in (1, 2)]
        pd.testing.assert_frame_equal(frames[0], frames[1])
        evals = [experiments[w].read_phase_record(round_index).eval for w in (1, 2)]
        assert evals[0] == evals[1] and evals[0] is not None


def test_resuming_with_another_worker_count_is_allowed(tmp_path):
    args = [*TOY_RUN, f"--output_dir={tmp_path / 'exp'}", "--dagger.rounds=1"]
    run(draccus.parse(RunConfig, args=[*args, "--rollout.workers=2"]))
    lines = run(draccus.parse(RunConfig, args=[*args, "--rollout.workers=0", "--resume=true"]))
    assert len(lines) == 2


def test_a_worker_killed_mid_collection_raises_instead_of_hanging(suite):
    with EnvWorkers(suite, 2) as env_workers:
        victim = env_workers._processes[1]
        calls = []

        def learner_that_kills_a_worker(observations, tasks):
            calls.append(1)
            if len(calls) == 3:
                os.kill(victim.pid, signal.SIGKILL)
            return tilted_learner(observations, tasks)

        options = EpisodeOptions(
            beta=0.0,
            seed=0,
            round_index=1,
            stream=COLLECT_STREAM,
            record=True,
            max_steps=30,
            steps_after_success=0,
        )
        with pytest.raises(WorkerDiedError, match=r"Env worker 1 \(pid \d+\) died .* --resume=true"):
            run_episodes(env_workers, [3, 3, 3], options, policy=learner_that_kills_a_worker)


class FailingExpert:
    """An expert that breaks on its fifth action."""

    def __init__(self, expert):
        self.expert, self.calls = expert, 0

    def reset(self):
        self.expert.reset()

    def act(self, privileged_state):
        self.calls += 1
        if self.calls == 5:
            raise ArithmeticError("expert broke on purpose")
        return self.expert.act(privileged_state)


@pytest.mark.parametrize("workers", [0, 2])
def test_an_error_inside_a_worker_is_re_raised_with_its_traceback(suite, workers):
    broken = suite.with_experts({"toy-up-windy": FailingExpert(make_expert(suite, "toy-up-windy"))})
    with pytest.raises(ArithmeticError, match="expert broke on purpose") as caught:
        collect(broken, workers, counts=(1, 1, 1), beta=1.0, policy=None)
    if workers:
        cause = caught.value.__cause__
        assert isinstance(cause, RemoteWorkerError)
        assert "ArithmeticError: expert broke on purpose" in cause.text
        assert "in act" in cause.text and "test_workers.py" in cause.text  # the worker's own frames


def test_negative_worker_counts_are_refused(suite):
    with pytest.raises(ValueError, match="workers must be >= 0"):
        EnvWorkers(suite, -1)
    with pytest.raises(ValueError, match="workers must be >= 0"):
        RunConfig(suite=SuiteConfig(name="toy"), rollout=RolloutConfig(workers=-2))


@pytest.mark.parametrize(("tasks", "workers"), [(10, 2), (50, 2), (10, 3), (7, 2)])
def test_lanes_are_spread_evenly_over_the_workers(tasks, workers):
    """Every worker steps as many lanes as the others (within one), and so does each group's share.

    With 2 workers and MT10's 10 lanes in two groups of 5, spreading by group alone gave one
    worker 6 lanes and the other 4, and each cycle waited for the busier one.
    """
    from collections import deque

    from lerobot_mtdagger.runner.rollout.collect import LANE_GROUPS, _assign, _Lane, _Schedule

    lanes = [_Lane(home_task=task, group=task % LANE_GROUPS) for task in range(tasks)]
    schedule = _Schedule(
        [deque(range(3)) for _ in range(tasks)], seed=0, round_index=1, stream=COLLECT_STREAM
    )
    for handle in range(tasks):
        _assign(lanes, handle, schedule, workers)
    per_worker = [sum(lane.worker == w for lane in lanes) for w in range(workers)]
    assert max(per_worker) - min(per_worker) <= 1, per_worker
    for group in range(LANE_GROUPS):
        shares = [sum(lane.worker == w and lane.group == group for lane in lanes) for w in range(workers)]
        assert max(shares) - min(shares) <= 1, (group, shares)
