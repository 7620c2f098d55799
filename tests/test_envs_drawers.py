"""Tests of the drawer suite on real MuJoCo scenes (MetaWorld's Sawyer arena, EGL rendering)."""

from __future__ import annotations

import dataclasses
import os
import warnings

import numpy as np
import pytest

from lerobot_mtdagger.commands.configs.eval import EvalConfig
from lerobot_mtdagger.envs import (
    IMAGE_KEY,
    POINTCLOUD_KEY,
    STATE_KEY,
    ObservationConfig,
    SuiteConfig,
    make_suite,
    suite_from_config,
)
from lerobot_mtdagger.envs.drawers.catalogue import (
    DRAWER_TASKS,
    HELDOUT_DRAWERS,
    HELDOUT_TASKS,
    TRAINING_DRAWERS,
    VARIANTS,
)
from lerobot_mtdagger.envs.drawers.pictures import render_drawer_picture
from lerobot_mtdagger.envs.drawers.scene import DrawerSceneEnv
from lerobot_mtdagger.envs.drawers.variants import (
    DRAWER_STATE_NAMES,
    PLACEMENTS,
    STATE_INDEX,
    SUCCESS_FRACTION,
    TABLE_X_LIMIT,
    TABLE_Y_RANGE,
)
from lerobot_mtdagger.envs.lerobot_env import LeRobotSuiteEnv, MTDAggerSuiteEnvConfig
from lerobot_mtdagger.experts import make_expert, run_expert_episode
from lerobot_mtdagger.experts.drawers import DrawerScriptedExpert

ALL_DRAWERS = DRAWER_TASKS + HELDOUT_TASKS
EXPERT_TARGET = 0.95


def expert_success_rate(suite, task_name: str, seeds) -> float:
    env = suite.make_env(task_name)
    expert = make_expert(suite, task_name)
    try:
        return float(np.mean([run_expert_episode(env, expert, seed).success for seed in seeds]))
    finally:
        env.close()


def test_suite_has_eleven_training_drawers_and_unseen_heldout_ones():
    suite = make_suite("drawers")
    assert suite.task_names == list(DRAWER_TASKS) and len(DRAWER_TASKS) == 11
    assert len(suite.heldout_task_names) >= 3
    assert not set(suite.heldout_task_names) & set(suite.task_names)
    assert "drawer-kitchen" in suite.task_names
    handles = {VARIANTS[t].handle for t in suite.task_names}
    assert handles == {"bar", "knob", "lip", "vbar"}
    for name in ALL_DRAWERS:
        assert name.startswith(f"drawer-{VARIANTS[name].handle}") or name == "drawer-kitchen"


def test_heldout_drawers_differ_from_every_training_drawer():
    training = np.stack([v.parameter_vector() for v in TRAINING_DRAWERS])
    scale = training.std(axis=0) + 1e-9
    for variant in HELDOUT_DRAWERS:
        vector = variant.parameter_vector()
        differing = np.abs(training - vector) > 1e-9
        # Every training drawer differs from it in several parameters, not just a colour or a name.
        assert differing.sum(axis=1).min() >= 5, variant.name
        assert (np.abs(training - vector) / scale).sum(axis=1).min() > 3.0, variant.name


@pytest.mark.parametrize("name", ALL_DRAWERS)
def test_every_drawer_builds_and_starts_closed(name):
    env = DrawerSceneEnv(VARIANTS[name])
    try:
        env.seed(0)
        state, _ = env.reset()
        assert state.shape == (len(DRAWER_STATE_NAMES),) and np.all(np.isfinite(state))
        assert state[STATE_INDEX["opening"]] == 0.0
        assert state[STATE_INDEX["travel"]] == VARIANTS[name].travel
        axis = state[[STATE_INDEX["axis_x"], STATE_INDEX["axis_y"], STATE_INDEX["axis_z"]]]
        assert np.isclose(np.linalg.norm(axis), 1.0) and axis[1] < -0.8  # opens towards the robot
        assert not env.fingers_touch_handle()
    finally:
        env.close()


@pytest.mark.parametrize("placement", sorted(PLACEMENTS))
def test_seeded_resets_place_the_case_reproducibly_within_the_range(placement):
    suite = make_suite("drawers", tasks=["drawer-bar-wide"], placement=placement)
    env = suite.make_env("drawer-bar-wide")
    variant, ranges = VARIANTS["drawer-bar-wide"], PLACEMENTS[placement]
    try:
        first = env.reset(seed=3)[1]["privileged_state"]
        other = env.reset(seed=4)[1]["privileged_state"]
        again = env.reset(seed=3)[1]["privileged_state"]
        np.testing.assert_array_equal(first, again)
        assert not np.allclose(first, other)
        poses, colours = [], []
        model = env._env.model
        for seed in range(20):
            env.reset(seed=seed)
            yaw = 2 * np.degrees(
                np.arctan2(model.body("drawer_case").quat[3], model.body("drawer_case").quat[0])
            )
            poses.append([*model.body("drawer_case").pos, yaw])
            colours.append(
                model.geom_rgba[[model.geom(n).id for n in ("case_top", "drawer_front", "handle_bar")]]
            )
        offsets = np.array(poses) - np.array([variant.x, variant.y, variant.elevation, variant.yaw])
        limits = np.array([ranges.x, ranges.y, ranges.lift, ranges.yaw])
        assert np.all(np.abs(offsets) <= limits + 1e-6) and np.all(offsets[:, 2] >= 0)
        assert offsets[:, [0, 1, 3]].std(axis=0).min() > ranges.y / 6
        colours = np.array(colours)
        shifts = colours - np.array([variant.case_rgba, variant.front_rgba, variant.handle_rgba])
        assert np.all(np.abs(shifts) <= ranges.colour + 1e-6)
        if placement == "narrow":
            assert np.all(offsets[:, 2] == 0) and np.abs(shifts).max() < 1e-6  # float32 colours
            # The first setting's exact offsets: a deep case is not moved back from the back wall.
            assert offsets[:, 1].max() > 0.01
        else:
            assert offsets[:, 2].std() > 0.01 and shifts[..., :3].std() > 0.05
    finally:
        env.close()


def test_the_kitchen_placement_keeps_every_drawer_on_the_table():
    """Shifts that would push a deep case through the back wall move it towards the robot instead."""
    suite = make_suite("drawers", tasks=ALL_DRAWERS, placement="kitchen")
    for name in ALL_DRAWERS:
        env = suite.make_env(name)
        try:
            for seed in range(10):
                env.reset(seed=seed)
                scene = env._env
                case = scene.data.body("drawer_case")
                yaw = np.arctan2(case.xmat[3], case.xmat[0])
                corners = VARIANTS[name].case_corners_xy(case.xpos[0], case.xpos[1], yaw)
                assert np.all(np.abs(corners[:, 0]) <= TABLE_X_LIMIT + 1e-9), name
                assert np.all(
                    (corners[:, 1] >= TABLE_Y_RANGE[0] - 1e-9) & (corners[:, 1] <= TABLE_Y_RANGE[1] + 1e-9)
                )
        finally:
            env.close()


def test_an_unknown_placement_is_a_clear_error():
    with pytest.raises(ValueError, match="choose one of .*kitchen.*narrow"):
        make_suite("drawers", placement="office")
    with pytest.raises(ValueError, match="drawers suite only"):
        make_suite("toy", placement="narrow")


@pytest.mark.parametrize("name", ["drawer-knob-small", "drawer-lip-heavy"])
def test_expert_opens_two_drawers_in_seeded_episodes(name):
    suite = make_suite("drawers")
    assert expert_success_rate(suite, name, range(1000, 1020)) >= EXPERT_TARGET


@pytest.mark.slow
@pytest.mark.parametrize("name", ALL_DRAWERS)
def test_expert_opens_every_drawer_in_seeded_episodes(name):
    suite = make_suite("drawers")
    assert expert_success_rate(suite, name, range(2000, 2040)) >= EXPERT_TARGET


def test_progress_counts_touch_pull_and_opening_and_never_decreases():
    suite = make_suite("drawers", tasks=["drawer-bar-narrow"])
    env = suite.make_env("drawer-bar-narrow", seed=5)
    expert = make_expert(suite, "drawer-bar-narrow")
    travel = VARIANTS["drawer-bar-narrow"].travel
    try:
        _, info = env.reset()
        assert info["progress"] == 0 and info["opening"] == 0.0
        progress = []
        for _ in range(150):
            _, _, _, _, info = env.step(expert.act(info["privileged_state"]))
            progress.append(info["progress"])
            if info["success"]:
                break
        assert info["success"] and info["opening"] >= SUCCESS_FRACTION * travel
        assert progress[-1] == 3 and progress[0] == 0
        assert set(progress) == {0, 1, 2, 3} and np.all(np.diff(progress) >= 0)
    finally:
        env.close()


def test_doing_nothing_or_pulling_without_the_handle_does_not_open_a_drawer():
    suite = make_suite("drawers", tasks=["drawer-kitchen"])
    env = suite.make_env("drawer-kitchen", seed=0)
    try:
        _, info = env.reset()
        for _ in range(60):
            _, _, _, _, info = env.step(np.zeros(4, dtype=np.float32))
        assert info["opening"] < 1e-3 and info["progress"] == 0
        for _ in range(60):  # sweep towards the robot above the drawer, gripper closed
            _, _, _, _, info = env.step(np.array([0.0, -1.0, 0.3, 1.0], dtype=np.float32))
        assert not info["success"] and info["opening"] < 0.01
    finally:
        env.close()


def test_expert_recovers_from_states_a_learner_left_behind():
    """DAgger labels learner states: after random actions (gripper closed, drawer nudged) it still opens."""
    suite = make_suite("drawers", tasks=["drawer-vbar-tall"])
    env = suite.make_env("drawer-vbar-tall")
    expert = make_expert(suite, "drawer-vbar-tall")
    rng = np.random.default_rng(0)
    successes = []
    try:
        for seed in range(6):
            _, info = env.reset(seed=seed)
            for _ in range(40):
                _, _, _, _, info = env.step(rng.uniform(-1, 1, 4).astype(np.float32))
            success = False
            for _ in range(220):
                _, _, _, truncated, info = env.step(expert.act(info["privileged_state"]))
                success = success or info["success"]
                if success or truncated:
                    break
            successes.append(success)
    finally:
        env.close()
    assert np.mean(successes) >= 5 / 6


def close_and_pull(suite, name: str, lateral: float, seed: int = 3) -> float:
    """Opening (fraction of travel) after closing the gripper ``lateral`` metres off the grasp pose
    across the pull axis (approached from above, as a learner does) and pulling for 40 steps."""
    env = suite.make_env(name)
    expert = DrawerScriptedExpert(VARIANTS[name])

    def point(state, prefix):
        return np.array([state[STATE_INDEX[f"{prefix}_{axis}"]] for axis in "xyz"])

    try:
        _, info = env.reset(seed=seed)
        state = info["privileged_state"]
        while expert.decide(state)[0] not in ("grip",):
            state = env.step(expert.act(state))[4]["privileged_state"]
        axis = point(state, "axis")
        across = np.array([-axis[1], axis[0], 0.0])
        # Up 5 cm, sideways above the handle, down to the grasp height: (sideways, height, steps).
        for sideways, height, steps in ((0.0, 0.05, 10), (lateral, 0.05, 15), (lateral, 0.0, 20)):
            for _ in range(steps):
                target = point(state, "grasp") + sideways * across + np.array([0.0, 0.0, height])
                move = np.clip(12.0 * (target - point(state, "hand")), -1, 1)
                state = env.step(np.append(move, -1.0).astype(np.float32))[4]["privileged_state"]
        for _ in range(15):
            state = env.step(np.array([0, 0, 0, 1.0], dtype=np.float32))[4]["privileged_state"]
        for _ in range(40):
            pull = np.append(0.8 * point(state, "axis"), 1.0).astype(np.float32)
            state = env.step(pull)[4]["privileged_state"]
        return state[STATE_INDEX["opening"]] / state[STATE_INDEX["travel"]]
    finally:
        env.close()


@pytest.mark.parametrize("name", ["drawer-vbar-tall", "drawer-knob-large"])
def test_the_expert_holds_where_closing_catches_the_handle(name):
    """The expert's holding range across the pull axis is the physical one: a pull from just inside it
    opens the drawer, one from beyond it does not (a centimetre out: the pad misses the handle)."""
    suite = make_suite("drawers", tasks=[name])
    reach = DrawerScriptedExpert.holding_half_width(VARIANTS[name])
    assert close_and_pull(suite, name, reach - 0.003) >= SUCCESS_FRACTION
    assert close_and_pull(suite, name, reach + 0.012) < 0.1


@pytest.mark.parametrize("name", ALL_DRAWERS)
def test_point_clouds_cover_the_handle(name):
    suite = make_suite("drawers", observation=ObservationConfig(obs_mode="pointcloud", num_points=1024))
    env = suite.make_env(name, seed=1)
    try:
        observation, _ = env.reset()
        cloud = observation[POINTCLOUD_KEY]
        assert cloud.shape == (1024, 3) and cloud.dtype == np.float32
        raw = env._env
        on_handle = raw.handle_distance(cloud) < 0.005
        off_front = raw.surface_distance(cloud, ["drawer_front"]) > 0.008
        assert (on_handle & off_front).sum() >= 3  # points on the handle itself, not the front panel
        assert cloud[:, 2].min() > 0.0  # the table top is cropped away
        assert observation[STATE_KEY].shape == (4,)
    finally:
        env.close()


def test_rgb_and_state_observations_match_the_suite_features():
    for obs_mode in ("state", "rgb"):
        suite = make_suite("drawers", observation=ObservationConfig(obs_mode=obs_mode, image_size=64))
        env = suite.make_env("drawer-lip-wide", seed=0)
        try:
            observation, info = env.reset()
            _, _, _, _, info = env.step(np.zeros(4, dtype=np.float32))
        finally:
            env.close()
        features = suite.features
        assert set(observation) == set(features) - {"action"}
        for key, value in observation.items():
            assert value.shape == tuple(features[key]["shape"]), key
        if obs_mode == "rgb":
            assert observation[IMAGE_KEY].dtype == np.uint8 and observation[IMAGE_KEY].std() > 5
        else:
            assert features[STATE_KEY]["names"] == DRAWER_STATE_NAMES
        assert {"success", "progress", "opening", "privileged_state"} <= set(info)


def test_heldout_drawers_build_for_evaluation_but_are_not_tasks():
    suite = make_suite("drawers")
    name = suite.heldout_task_names[0]
    env = suite.make_env(name, seed=0)
    try:
        _, info = env.reset()
        action = make_expert(suite, name).act(info["privileged_state"])
    finally:
        env.close()
    assert action.shape == (4,) and np.all(np.abs(action) <= 1.0)
    with pytest.raises(ValueError, match="is not in suite"):
        suite.task_index(name)
    with pytest.raises(ValueError, match="neither a task"):
        make_suite("drawers", tasks=["drawer-bar-wide"]).make_env("drawer-knob-large")
    with pytest.raises(ValueError, match="Unknown drawer"):
        make_suite("drawers", tasks=["drawer-nope"])


def test_a_suite_of_heldout_drawers_can_be_built_for_training_too():
    suite = make_suite("drawers", tasks=list(HELDOUT_TASKS[:2]))
    assert suite.task_names == list(HELDOUT_TASKS[:2])
    assert not set(suite.heldout_task_names) & set(suite.task_names)


def test_user_defined_variants_join_a_suite():
    from lerobot_mtdagger.envs.base import ObservationConfig
    from lerobot_mtdagger.envs.drawers.suite import DrawerSuite

    mine = dataclasses.replace(
        VARIANTS["drawer-bar-wide"], name="drawer-bar-mine", travel=0.1, yaw=-12.0, y=0.72
    )
    suite = DrawerSuite(["drawer-bar-mine"], ObservationConfig(), variants=[mine])
    assert expert_success_rate(suite, "drawer-bar-mine", range(5)) == 1.0


BAD_VARIANTS = [
    ({"width": -0.2}, "width must be a positive length"),
    ({"handle_size": -0.1}, "handle_size must be a positive length"),
    ({"travel": 0.0}, "travel must be > 0"),
    ({"travel": 0.5}, "make the case deeper or the travel shorter"),
    ({"handle": "hook"}, "handle must be one of"),
    ({"damping": -1.0}, "damping must be >= 0"),
    ({"x": 0.55}, "off the table"),
    ({"y": 0.9}, "move y or make the case shallower"),
    ({"handle_clearance": 0.01}, "no room for a finger"),
    ({"handle_height": 0.95}, "move handle_height towards 0"),
    ({"yaw": 45.0}, "yaw must be within"),
    ({"front_rgba": (1.0, 0.0, 0.0)}, "front_rgba must be 4 numbers"),
    ({"name": "bar-wide"}, "start with 'drawer-'"),
]


@pytest.mark.parametrize(("change", "message"), BAD_VARIANTS)
def test_bad_variant_parameters_are_clear_errors(change, message):
    with pytest.raises(ValueError, match=message):
        dataclasses.replace(VARIANTS["drawer-bar-wide"], **change)


def test_lip_handles_sit_on_the_top_edge():
    with pytest.raises(ValueError, match="set handle_height=0"):
        dataclasses.replace(VARIANTS["drawer-lip-wide"], handle_height=0.2)


def test_vector_env_steps_drawers_in_worker_processes():
    suite = make_suite("drawers", tasks=["drawer-bar-wide", "drawer-knob-small"])
    envs = suite.make_vector_env(suite.task_names, seeds=[0, 1])
    try:
        workers = [process.pid for process in envs.processes if process.is_alive()]
        assert len(set(workers)) == 2 and os.getpid() not in workers
        _, infos = envs.reset()
        _, _, _, _, infos = envs.step(np.zeros((2, 4), dtype=np.float32))
        assert infos["privileged_state"].shape == (2, len(DRAWER_STATE_NAMES))
        assert list(infos["progress"]) == [0, 0]
        travel = infos["privileged_state"][:, STATE_INDEX["travel"]]
        assert list(travel) == pytest.approx([0.15, 0.10])  # each worker holds its own drawer
    finally:
        envs.close()
    assert not any(process.is_alive() for process in envs.processes)


def test_lerobot_env_plugin_builds_a_drawer():
    env = LeRobotSuiteEnv(suite={"name": "drawers", "obs_mode": "state"}, task="drawer-kitchen")
    try:
        observation, _ = env.reset(seed=0)
        assert observation["agent_pos"].shape == (len(DRAWER_STATE_NAMES),)
        assert env.task_description == "drawer-kitchen"
    finally:
        env.close()


def test_lerobot_s_env_check_finds_the_task_it_passes_to_the_policy():
    """lerobot-eval warns on every run unless an env gives ``task_description`` and ``task`` (both lines)."""
    import gymnasium as gym
    from lerobot.envs.utils import check_env_attributes_and_types

    suite = {"name": "drawers", "obs_mode": "state"}
    envs = gym.vector.SyncVectorEnv([lambda: LeRobotSuiteEnv(suite=suite, task="drawer-kitchen")])
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            check_env_attributes_and_types(envs)
        assert envs.envs[0].task == envs.envs[0].task_description == "drawer-kitchen"
    finally:
        envs.close()


@pytest.mark.parametrize("placement", [None, "narrow"])
def test_the_lerobot_env_plugin_and_eval_take_the_placement(placement):
    """``--env.suite.placement`` (lerobot-eval) and ``eval --suite.placement`` reach the drawers (kitchen)."""
    config = MTDAggerSuiteEnvConfig(
        suite=SuiteConfig(name="drawers", placement=placement), task="drawer-kitchen"
    )
    assert config.gym_kwargs["suite"]["placement"] == placement
    env = LeRobotSuiteEnv(**config.gym_kwargs)
    try:
        assert env._suite.placement.name == (placement or "kitchen")
    finally:
        env.close()
    eval_config = EvalConfig(
        policy_path="unused",
        suite=SuiteConfig(
            name="drawers", obs_mode="state", num_points=512, image_size=84, placement=placement
        ),
    )
    assert suite_from_config(eval_config.suite).placement.name == (placement or "kitchen")


def test_pictures_show_the_drawer():
    picture = render_drawer_picture(VARIANTS["drawer-kitchen"], height=96, width=128)
    assert picture.shape == (96, 128, 3) and picture.dtype == np.uint8
    assert picture.std() > 10
    with pytest.raises(ValueError, match="opening_fraction"):
        render_drawer_picture(VARIANTS["drawer-kitchen"], opening_fraction=2.0)
