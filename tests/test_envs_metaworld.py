"""Tests of the MetaWorld suites on real MuJoCo environments (rendering through EGL)."""

from __future__ import annotations

import os

import gymnasium as gym
import numpy as np
import pytest
import torch

from benchmarks.bench_cloud import former_cloud
from lerobot_mtdagger.envs import (
    IMAGE_KEY,
    POINTCLOUD_KEY,
    STATE_KEY,
    SUITE_NAMES,
    ObservationConfig,
    make_suite,
)
from lerobot_mtdagger.envs.metaworld import METAWORLD_CROP, MT10_TASKS, MT25_TASKS, MT50_TASKS
from lerobot_mtdagger.experts import CallableExpert, LeRobotPolicyExpert, make_expert
from lerobot_mtdagger.experts import run_expert_episode as expert_episode

MODES = ("state", "rgb", "pointcloud")


def run_expert_episode(suite, task_name: str, seed: int) -> tuple[bool, int]:
    """Runs the task's expert for one seeded episode; success if info["success"] at any step."""
    env = suite.make_env(task_name)
    try:
        episode = expert_episode(env, make_expert(suite, task_name), seed)
        return episode.success, episode.steps
    finally:
        env.close()


def test_suite_task_lists_are_metaworlds():
    assert len(MT10_TASKS) == 10 and len(MT25_TASKS) == 25 and len(MT50_TASKS) == 50
    assert make_suite("metaworld-mt10").task_names == list(MT10_TASKS)
    assert make_suite("metaworld-mt50").task_names == list(MT50_TASKS)
    subset = make_suite("metaworld-mt10", tasks=["push-v3", "reach-v3"])
    assert subset.task_names == ["push-v3", "reach-v3"]
    assert subset.task_index("reach-v3") == 1
    custom = make_suite("metaworld", tasks=["hammer-v3", "reach-v3"])
    assert custom.task_names == ["hammer-v3", "reach-v3"]


@pytest.mark.parametrize("obs_mode", MODES)
@pytest.mark.parametrize("task_name", MT10_TASKS)
def test_observations_match_features(task_name, obs_mode):
    suite = make_suite(
        "metaworld-mt10", observation=ObservationConfig(obs_mode=obs_mode, num_points=256, image_size=64)
    )
    env = suite.make_env(task_name, seed=0)
    try:
        observation, info = env.reset()
        assert env.observation_space.contains(observation)
        observation, _, _, _, info = env.step(env.action_space.sample())
        features = {k: v for k, v in suite.features.items() if k != "action"}
        assert set(observation) == set(features)
        for key, feature in features.items():
            assert observation[key].shape == tuple(feature["shape"]), key
            expected = np.uint8 if feature["dtype"] == "image" else np.dtype(feature["dtype"])
            assert observation[key].dtype == expected, key
        assert isinstance(info["success"], bool)
        assert info["privileged_state"].shape == (39,)
        assert suite.features["action"]["shape"] == (4,)
    finally:
        env.close()


def test_state_mode_shows_the_goal_and_matches_privileged_state():
    suite = make_suite("metaworld-mt10", tasks=["reach-v3"])
    env = suite.make_env("reach-v3", seed=3)
    observation, info = env.reset()
    np.testing.assert_allclose(observation[STATE_KEY], info["privileged_state"].astype(np.float32))
    assert np.any(observation[STATE_KEY][36:39] != 0), "the goal must be visible in state mode"
    env.close()


def test_seeded_resets_are_reproducible():
    suite = make_suite("metaworld-mt10")
    first, second = suite.make_env("push-v3", seed=11), suite.make_env("push-v3")
    _, info_a = first.reset()
    _, info_b = second.reset(seed=11)
    np.testing.assert_array_equal(info_a["privileged_state"], info_b["privileged_state"])
    _, info_c = second.reset(seed=12)
    assert not np.allclose(info_a["privileged_state"][36:39], info_c["privileged_state"][36:39])
    # An unseeded reset continues the random stream: a new initial state.
    _, info_d = first.reset()
    assert not np.allclose(info_a["privileged_state"][4:7], info_d["privileged_state"][4:7])
    first.close()
    second.close()


def test_episodes_truncate_at_max_episode_steps_and_require_reset():
    suite = make_suite("metaworld-mt10", max_episode_steps=5)
    env = suite.make_env("reach-v3", seed=0)
    env.reset()
    flags = [env.step(np.zeros(4))[3] for _ in range(5)]
    assert flags == [False, False, False, False, True]
    with pytest.raises(RuntimeError, match="call reset"):
        env.step(np.zeros(4))
    env.reset()
    env.step(np.zeros(4))
    env.close()


@pytest.mark.parametrize("task_name", MT10_TASKS)
def test_scripted_expert_succeeds(task_name):
    suite = make_suite("metaworld-mt10")
    results = [run_expert_episode(suite, task_name, seed)[0] for seed in (0, 1)]
    # The expert succeeds on ~98% of episodes; door-open and peg-insert-side fail occasionally.
    assert sum(results) >= 1, f"{task_name}: expert failed on both seeded episodes"


@pytest.mark.slow
def test_scripted_expert_success_rate_over_mt10():
    suite = make_suite("metaworld-mt10")
    rates = {}
    for task_name in MT10_TASKS:
        rates[task_name] = np.mean([run_expert_episode(suite, task_name, 100 + s)[0] for s in range(10)])
    assert np.mean(list(rates.values())) >= 0.95, rates
    assert min(rates.values()) >= 0.7, rates


# ---------------------------------------------------------------------------------------------
# Point clouds and images
# ---------------------------------------------------------------------------------------------


def test_point_cloud_is_exact_finite_and_inside_the_crop():
    suite = make_suite("metaworld-mt10", observation=ObservationConfig(obs_mode="pointcloud", num_points=512))
    env = suite.make_env("push-v3", seed=0)
    observation, _ = env.reset()
    cloud = observation[POINTCLOUD_KEY]
    assert cloud.shape == (512, 3) and cloud.dtype == np.float32
    assert np.all(np.isfinite(cloud))
    assert np.all(METAWORLD_CROP.contains(cloud.astype(np.float64)))
    assert cloud[:, 2].min() >= METAWORLD_CROP.low[2], "the table top must be cropped away"
    env.close()


@pytest.mark.parametrize(
    ("suite_name", "task", "color"),
    [
        ("metaworld-mt10", "push-v3", False),
        ("drawers", "drawer-kitchen", False),
        ("drawers", "drawer-knob-deep", True),
    ],
)
def test_the_cloud_is_the_former_row_by_row_back_projection(suite_name, task, color):
    """Back-projecting per coordinate plane (fast) keeps the points, their order and the sampling."""
    suite = make_suite(
        suite_name,
        observation=ObservationConfig(obs_mode="pointcloud", num_points=600, pointcloud_color=color),
    )
    env = suite.make_env(task, seed=2)
    env.reset(seed=2)
    camera, data = env.unwrapped._cloud, env.unwrapped._env.data
    for step in range(4):
        env.step(np.array([0.6, -0.4, -0.8, 0.3]) * (-1) ** step)
        seed = np.random.default_rng(step).integers(1 << 30)
        new = camera.capture(data, np.random.default_rng(seed))
        old = former_cloud(camera, data, np.random.default_rng(seed))
        assert new.shape == old.shape == (600, 6 if color else 3)
        np.testing.assert_allclose(new, old, rtol=0, atol=1e-6)
    env.close()


def test_point_cloud_follows_the_arm():
    suite = make_suite(
        "metaworld-mt10", observation=ObservationConfig(obs_mode="pointcloud", num_points=4096)
    )
    env = suite.make_env("reach-v3", seed=0)
    observation, info = env.reset()
    before = observation[POINTCLOUD_KEY]
    hand_before = info["privileged_state"][:3]
    for _ in range(25):
        observation, _, _, _, info = env.step(np.array([1.0, 0.0, 0.0, 0.0]))
    after = observation[POINTCLOUD_KEY]
    hand_after = info["privileged_state"][:3]
    assert hand_after[0] - hand_before[0] > 0.1, "the arm must have moved sideways"

    def near(cloud, point, radius=0.06):
        return int((np.linalg.norm(cloud - point, axis=1) < radius).sum())

    assert near(after, hand_after) > 0, "points must cover the gripper at its new position"
    assert near(after, hand_after) > 2 * near(before, hand_after)
    assert near(before, hand_before) > 2 * near(after, hand_before)
    env.close()


def test_a_simplified_render_model_differs_only_on_the_meshes_it_simplified():
    """``mesh_detail`` renders the arm with fewer faces: every other pixel's depth stays exact."""
    import mujoco

    from lerobot_mtdagger.envs.rendering import MIN_FACES_TO_SIMPLIFY, simplified_model

    env = make_suite(
        "metaworld-mt10", observation=ObservationConfig(obs_mode="pointcloud", num_points=64)
    ).make_env("push-v3", seed=0)
    env.reset()
    for _ in range(10):
        env.step(np.array([0.5, 0.5, -0.5, 0.0]))
    model, data = env.unwrapped._env.model, env.unwrapped._env.data
    faces = model.mesh_facenum.sum()
    simple = simplified_model(model, 0.2)
    assert model.mesh_facenum.sum() == faces, "the physics model is not modified"
    assert simple.mesh_facenum.sum() < 0.3 * faces
    big = [i for i in range(model.nmesh) if model.mesh_facenum[i] >= MIN_FACES_TO_SIMPLIFY]
    simplified_geoms = [g for g in range(model.ngeom) if model.geom_dataid[g] in big]

    def frames(render_model):
        renderer = mujoco.Renderer(render_model, 84, 84)
        renderer.update_scene(data, camera="corner")
        renderer.enable_depth_rendering()
        depth = renderer.render().copy()
        renderer.disable_depth_rendering()
        renderer.enable_segmentation_rendering()
        geoms = renderer.render()[..., 0].copy()
        renderer.close()
        return depth, geoms

    (depth, geoms), (simple_depth, simple_geoms) = frames(model), frames(simple)
    changed = np.abs(depth - simple_depth) > 1e-4
    on_simplified = np.isin(geoms, simplified_geoms) | np.isin(simple_geoms, simplified_geoms)
    assert changed.any() and np.isin(geoms, simplified_geoms).mean() > 0.05, "the arm is in view"
    assert not (changed & ~on_simplified).any()
    env.close()


@pytest.mark.parametrize("obs_mode", ["rgb", "pointcloud"])
def test_observation_renderers_have_no_shadow_map_and_the_same_frames(obs_mode):
    """64 MiB per env saved on Mesa: the context has no shadow map, the model keeps its size, frames agree."""
    import mujoco

    env = make_suite(
        "metaworld-mt10", observation=ObservationConfig(obs_mode=obs_mode, num_points=64)
    ).make_env("push-v3", seed=0)
    env.reset()
    for _ in range(10):
        env.step(np.array([0.5, 0.5, -0.5, 0.0]))
    scene, data = env.unwrapped._renderer, env.unwrapped._env.data
    assert scene._renderer._mjr_context.shadowSize == 0
    assert scene.model.vis.quality.shadowsize == 4096, "the model shared with the physics is unchanged"
    with_map = mujoco.Renderer(scene.model, scene.height, scene.width)
    assert with_map._mjr_context.shadowSize == 4096
    frames = [scene.rgb(data, "corner"), scene.depth(data, "corner")]
    scene._renderer, original = with_map, scene._renderer
    try:
        assert np.array_equal(frames[0], scene.rgb(data, "corner"))
        assert np.array_equal(frames[1], scene.depth(data, "corner"))
    finally:
        scene._renderer = original
        with_map.close()
        env.close()


def test_mesh_detail_gives_clouds_of_the_same_scene():
    clouds, faces = [], []
    for detail in (1.0, 0.2):
        suite = make_suite(
            "metaworld-mt10",
            observation=ObservationConfig(obs_mode="pointcloud", num_points=512, mesh_detail=detail),
        )
        env = suite.make_env("push-v3", seed=3)
        observation, _ = env.reset()
        clouds.append(observation[POINTCLOUD_KEY])
        faces.append(int(env.unwrapped._renderer.model.mesh_facenum.sum()))
        env.close()
    assert faces[1] < 0.3 * faces[0], "the renderer draws the simplified model"
    assert np.all(METAWORLD_CROP.contains(clouds[1].astype(np.float64)))
    nearest = np.linalg.norm(clouds[1][:, None] - clouds[0][None], axis=2).min(axis=1)
    assert np.median(nearest) < 0.01, "the simplified scene's points lie on the exact scene"


def test_same_seed_gives_the_same_cloud():
    suite = make_suite("metaworld-mt10", observation=ObservationConfig(obs_mode="pointcloud", num_points=300))
    clouds = []
    for _ in range(2):
        env = suite.make_env("drawer-open-v3", seed=5)
        observation, _ = env.reset()
        observation, *_ = env.step(np.array([0.1, 0.2, 0.0, 0.5]))
        clouds.append(observation[POINTCLOUD_KEY])
        env.close()
    np.testing.assert_array_equal(clouds[0], clouds[1])


def test_point_cloud_with_color():
    suite = make_suite(
        "metaworld-mt10",
        observation=ObservationConfig(obs_mode="pointcloud", num_points=128, pointcloud_color=True),
    )
    env = suite.make_env("reach-v3", seed=0)
    observation, _ = env.reset()
    cloud = observation[POINTCLOUD_KEY]
    assert cloud.shape == (128, 6) == suite.features[POINTCLOUD_KEY]["shape"]
    assert np.all((cloud[:, 3:] >= 0) & (cloud[:, 3:] <= 1))
    env.close()


def where_the_arm_was(frames: list[np.ndarray]) -> tuple[np.ndarray, np.ndarray]:
    """Mean (row, column) of the arm at its first and at its last position, from 3 frames along a motion.

    A pixel that changed between the first and the middle frame but not between the middle and the
    last one shows the arm at its first position (the middle and last frames agree there), and vice
    versa. Renders are deterministic, so any change counts: no noise threshold.
    """
    first, middle, last = (frame.astype(int) for frame in frames)
    changed_early = np.any(middle != first, axis=-1)
    changed_late = np.any(last != middle, axis=-1)
    only_first, only_last = changed_early & ~changed_late, changed_late & ~changed_early
    assert only_first.any() and only_last.any(), "the arm must show at both ends of its motion"
    return np.argwhere(only_first).mean(axis=0), np.argwhere(only_last).mean(axis=0)


def test_rgb_image_is_upright_and_changes_with_the_arm():
    suite = make_suite("metaworld-mt10", observation=ObservationConfig(obs_mode="rgb", image_size=64))
    env = suite.make_env("reach-v3", seed=0)
    observation, info = env.reset()
    assert observation[IMAGE_KEY].shape == (64, 64, 3) and observation[IMAGE_KEY].dtype == np.uint8

    def move(action: list[float], steps: int) -> tuple[list[np.ndarray], np.ndarray]:
        """Images before, halfway through and after ``steps`` steps of ``action``; the hand's displacement."""
        nonlocal observation, info
        frames, hand_before = [observation[IMAGE_KEY].copy()], info["privileged_state"][:3].copy()
        for step in range(1, steps + 1):
            observation, _, _, _, info = env.step(np.array(action))
            if step in (steps // 2, steps):
                frames.append(observation[IMAGE_KEY].copy())
        return frames, info["privileged_state"][:3] - hand_before

    try:
        move([0.0, 0.0, -1.0, 0.0], 15)  # lower the hand towards the table first
        frames, displacement = move([0.0, 0.0, 1.0, 0.0], 30)
        assert displacement[2] > 0.15, "the hand must have risen"
        low, high = where_the_arm_was(frames)
        assert high[0] < low[0], (
            f"world up must be image up (row 0 at the top): rows {low[0]:.1f} -> {high[0]:.1f}"
        )

        move([-1.0, 0.0, 0.0, 0.0], 20)
        frames, displacement = move([1.0, 0.0, 0.0, 0.0], 40)
        assert displacement[0] > 0.2, "the hand must have moved along +x"
        start, end = where_the_arm_was(frames)
        # The corner camera looks along (+x, +y) from (-1.1, -0.4): world +x is on its right, so the
        # arm moves right unless the image is mirrored (flipped vertically instead of rotated).
        assert end[1] > start[1], f"+x must be to the right: columns {start[1]:.1f} -> {end[1]:.1f}"
    finally:
        env.close()


# ---------------------------------------------------------------------------------------------
# Experts
# ---------------------------------------------------------------------------------------------


def test_plugged_in_callable_expert_is_used():
    calls = []

    def expert(state):
        calls.append(state)
        return np.zeros(4)

    suite = make_suite("metaworld-mt10", tasks=["reach-v3"]).with_experts(
        {"reach-v3": CallableExpert(expert)}
    )
    action = make_expert(suite, "reach-v3").act(np.zeros(39))
    assert action.tolist() == [0.0, 0.0, 0.0, 0.0] and len(calls) == 1


class _TinyPolicy:
    """Stands in for a LeRobot PreTrainedPolicy: select_action maps (1, 39) -> (1, 4)."""

    def __init__(self):
        self.resets = 0

    def reset(self):
        self.resets += 1

    def select_action(self, batch):
        return batch["observation.state"][:, :4] * 2


def test_lerobot_policy_expert_adapter():
    policy = _TinyPolicy()
    expert = LeRobotPolicyExpert(policy, postprocessor=lambda a: torch.clamp(a, -1, 1))
    expert.reset()
    action = expert.act(np.array([0.1, -0.2, 0.9, 0.3] + [0.0] * 35))
    np.testing.assert_allclose(action, [0.2, -0.4, 1.0, 0.6], rtol=1e-6)
    assert policy.resets == 1


# ---------------------------------------------------------------------------------------------
# Vectorised collection and LeRobot datasets
# ---------------------------------------------------------------------------------------------


def test_vector_env_steps_several_tasks_in_parallel():
    suite = make_suite("metaworld-mt10", tasks=["reach-v3", "button-press-topdown-v3"])
    envs = suite.make_vector_env(suite.task_names, seeds=[0, 1])
    experts = [make_expert(suite, t) for t in suite.task_names]
    try:
        # One worker process per task, not in-process stepping (gymnasium's SyncVectorEnv): each
        # sub-env reports the pid of the process it lives in (os.getpid pickles by reference).
        assert isinstance(envs, gym.vector.AsyncVectorEnv), type(envs).__name__
        envs.set_attr("process_id", os.getpid)
        env_pids = envs.call("process_id")
        assert len(set(env_pids)) == 2 and os.getpid() not in env_pids, env_pids
        assert set(env_pids) == {process.pid for process in envs.processes}
        observation, info = envs.reset()
        assert observation[STATE_KEY].shape == (2, 39)
        succeeded = np.zeros(2, dtype=bool)
        for _ in range(200):
            actions = np.stack([e.act(s) for e, s in zip(experts, info["privileged_state"], strict=True)])
            observation, _, _, truncated, info = envs.step(actions)
            succeeded |= info["success"]
            if succeeded.all():
                break
        assert succeeded.all()
        assert all(process.is_alive() for process in envs.processes), "the workers must outlive the steps"
        observation, info = envs.reset(options={"reset_mask": np.array([True, False])})
    finally:
        envs.close()


@pytest.mark.parametrize("obs_mode", MODES)
def test_features_create_a_lerobot_dataset(tmp_path, obs_mode):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    suite = make_suite(
        "metaworld-mt10",
        tasks=["reach-v3"],
        observation=ObservationConfig(obs_mode=obs_mode, num_points=64, image_size=32),
    )
    dataset = LeRobotDataset.create(
        repo_id="local/test", fps=80, features=suite.features, root=tmp_path / "ds", use_videos=False
    )
    env = suite.make_env("reach-v3", seed=0)
    expert = make_expert(suite, "reach-v3")
    observation, info = env.reset()
    for _ in range(3):
        action = expert.act(info["privileged_state"])
        dataset.add_frame({**observation, "action": action, "task": "reach-v3"})
        observation, _, _, _, info = env.step(action)
    dataset.save_episode()
    dataset.finalize()
    env.close()
    loaded = LeRobotDataset("local/test", root=tmp_path / "ds")
    assert loaded.num_frames == 3
    item = loaded[1]
    for key, feature in suite.features.items():
        shape = tuple(feature["shape"])
        if feature["dtype"] == "image":
            shape = (shape[2], shape[0], shape[1])  # LeRobot returns images channel-first
        assert tuple(item[key].shape) == shape, key


# ---------------------------------------------------------------------------------------------
# Bad input
# ---------------------------------------------------------------------------------------------


@pytest.mark.parametrize(
    ("kwargs", "match"),
    [
        ({"name": "robosuite"}, "Unknown suite 'robosuite'; available suites"),
        ({"name": "metaworld-mt10", "tasks": ["hammer-v3"]}, r"not in metaworld-mt10; its tasks"),
        ({"name": "metaworld", "tasks": ["reach-v2"]}, r"Unknown MetaWorld v3 task\(s\) \['reach-v2'\]"),
        ({"name": "metaworld"}, "needs an explicit tasks"),
        ({"name": "metaworld-mt10", "obs_mode": "depth"}, r"Unknown obs_mode 'depth'; choose one of"),
        ({"name": "metaworld-mt10", "obs_mode": "pointcloud", "num_points": 0}, "num_points must be > 0"),
        ({"name": "metaworld-mt10", "tasks": ["reach-v3", "reach-v3"]}, "unique"),
        (
            {"name": "metaworld-mt10", "obs_mode": "rgb", "mesh_detail": 0.0},
            r"mesh_detail must be in \(0, 1\]",
        ),
    ],
)
def test_make_suite_rejects_bad_input(kwargs, match):
    kwargs = dict(kwargs)
    name, tasks = kwargs.pop("name"), kwargs.pop("tasks", None)
    with pytest.raises(ValueError, match=match):
        make_suite(name, tasks=tasks, observation=ObservationConfig(**kwargs))


def test_suite_names_are_listed():
    assert set(SUITE_NAMES) >= {"metaworld-mt10", "metaworld-mt25", "metaworld-mt50", "metaworld"}


def test_unknown_task_and_camera_in_make_env():
    suite = make_suite("metaworld-mt10", tasks=["reach-v3"])
    with pytest.raises(ValueError, match="not in suite"):
        suite.make_env("push-v3")
    rgb = make_suite(
        "metaworld-mt10",
        tasks=["reach-v3"],
        observation=ObservationConfig(obs_mode="rgb", camera="frontview"),
    )
    with pytest.raises(ValueError, match="Unknown camera 'frontview'; the model has cameras"):
        rgb.make_env("reach-v3")


def test_expert_with_wrong_action_size_is_a_clear_error():
    suite = make_suite("metaworld-mt10", tasks=["reach-v3"]).with_experts(
        {"reach-v3": CallableExpert(lambda state: np.zeros(3))}
    )
    with pytest.raises(
        ValueError, match=r"returned an action of size 3, but the task's action space has size 4"
    ):
        make_expert(suite, "reach-v3").act(np.zeros(39))


def test_object_without_act_is_not_an_expert():
    with pytest.raises(TypeError, match="wrap a function with CallableExpert"):
        make_suite("metaworld-mt10", tasks=["reach-v3"]).with_experts({"reach-v3": lambda s: s})


def test_bad_actions_are_rejected():
    env = make_suite("metaworld-mt10", tasks=["reach-v3"]).make_env("reach-v3", seed=0)
    env.reset()
    with pytest.raises(ValueError, match="4 finite numbers"):
        env.step(np.zeros(3))
    with pytest.raises(ValueError, match="4 finite numbers"):
        env.step(np.array([0.0, np.nan, 0.0, 0.0]))
    env.close()
