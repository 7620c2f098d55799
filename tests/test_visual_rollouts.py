"""The visual rollout path stores what the learner saw and what the expert said, step by step.

A DAgger round of a visual student is only as good as the pairing of each stored observation with
the expert's label of the SAME simulator state. These tests collect learner rollouts through the
env workers (pipelined lanes of several drawers; in this process: a worker forked from a test
process that has already rendered can hang in Mesa's EGL, and results never depend on the worker count,
``test_workers.py``), then replay every recorded episode
from its reset seed with the executed actions and compare each stored frame against a fresh render
and a fresh expert query of the replayed state. A frame from the wrong step, the wrong lane or a
reused buffer fails them.
"""

from __future__ import annotations

import numpy as np
import pytest

from lerobot_mtdagger.datasets.records import EXECUTED_ACTION, LEARNER_ACTED
from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.experts import make_expert
from lerobot_mtdagger.runner.rollout.collect import EpisodeOptions, run_episodes
from lerobot_mtdagger.runner.rollout.workers import EnvWorkers
from lerobot_mtdagger.utils.seeds import COLLECT_STREAM

DRAWERS = ["drawer-bar-wide", "drawer-knob-small", "drawer-lip-shallow"]
STATE = "observation.state"
CLOUD = "observation.pointcloud"


def wandering_learner(observations, tasks):
    """A deterministic learner whose actions depend on the observation (so lanes cannot be swapped)."""
    states = np.stack([o[STATE] for o in observations])  # (B, 4): hand xyz + gripper
    centroid = np.stack([o[CLOUD].mean(axis=0) for o in observations])  # (B, 3)
    move = np.tanh(8.0 * (centroid - states[:, :3]) * np.array([[1.0, 1.0, 0.3]]))
    grip = np.where(states[:, 2:3] < 0.15, 1.0, -1.0)
    return np.concatenate([move, grip], axis=1).astype(np.float32)


@pytest.fixture(scope="module")
def suite():
    return make_suite(
        "drawers",
        tasks=DRAWERS,
        observation=ObservationConfig(obs_mode="pointcloud", num_points=256, depth_size=48),
    )


@pytest.fixture(scope="module")
def episodes(suite):
    with EnvWorkers(suite, 0) as workers:
        options = EpisodeOptions(
            beta=0.5,
            seed=11,
            round_index=1,
            stream=COLLECT_STREAM,
            record=True,
            max_steps=25,
            steps_after_success=3,
            mixing="step",
        )
        return run_episodes(workers, [2, 1, 2], options, policy=wandering_learner)


def replay(suite, episode):
    """Fresh observations and expert labels of the states the episode's executed actions lead to."""
    env = suite.make_env(suite.task_names[episode.task_index])
    expert = make_expert(suite, suite.task_names[episode.task_index])
    try:
        observation, info = env.reset(seed=episode.seed)
        for frame in episode.frames:
            yield observation, expert.act(info["privileged_state"])
            observation, _, _, _, info = env.step(frame[EXECUTED_ACTION])
    finally:
        env.close()


def chamfer(a, b):
    """Symmetric mean nearest-neighbour distance between two (N, 3) clouds, metres."""
    distances = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return 0.5 * (distances.min(axis=1).mean() + distances.min(axis=0).mean())


def test_learner_and_expert_both_act(episodes):
    acted = np.concatenate([[bool(f[LEARNER_ACTED][0]) for f in e.frames] for e in episodes])
    assert acted.any() and not acted.all()
    assert len(episodes) == 5 and all(len(e.frames) > 0 for e in episodes)


def test_every_stored_frame_matches_a_fresh_render_of_its_state(suite, episodes):
    for episode in episodes:
        for step, (frame, (fresh, label)) in enumerate(
            zip(episode.frames, replay(suite, episode), strict=True)
        ):
            where = f"{suite.task_names[episode.task_index]} episode {episode.episode} step {step}"
            np.testing.assert_allclose(frame[STATE], fresh[STATE], atol=1e-5, err_msg=where)
            assert chamfer(frame[CLOUD], fresh[CLOUD]) < 1e-3, where
            np.testing.assert_allclose(frame["action"], label, atol=1e-5, err_msg=where)


def test_a_frame_of_the_neighbouring_step_would_be_caught(suite, episodes):
    """The tolerances above separate consecutive steps: the check can fail."""
    moving = 0
    for episode in episodes:
        fresh = [observation for observation, _ in replay(suite, episode)]
        for step in range(1, len(fresh)):
            hand_moved = np.abs(fresh[step][STATE][:3] - fresh[step - 1][STATE][:3]).max()
            if hand_moved > 1e-3:
                moving += 1
                assert np.abs(episode.frames[step][STATE][:3] - fresh[step - 1][STATE][:3]).max() > 1e-5
    assert moving > 20
