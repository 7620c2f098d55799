"""Stock ``lerobot-train`` and ``lerobot-eval`` on the ``mtdagger`` policy and our suites (subprocesses)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import torch
from lerobot.datasets.lerobot_dataset import LeRobotDataset
from lerobot.policies.factory import make_pre_post_processors

from lerobot_mtdagger.envs import ObservationConfig, make_suite
from lerobot_mtdagger.policies import MTDAggerPolicy
from tests.conftest import lerobot_train

BIN = Path(sys.executable).parent
TASKS = ["reach-v3", "button-press-topdown-v3"]


def lerobot_eval(
    checkpoint: Path,
    output_dir: Path,
    obs_mode: str,
    extra: list[str],
    suite: str = "metaworld-mt10",
    task: str = "reach-v3",
) -> dict:
    command = [
        str(BIN / "lerobot-eval"),
        f"--policy.path={checkpoint}",
        "--policy.device=cpu",
        "--env.discover_packages_path=lerobot_mtdagger.envs",
        "--env.type=mtdagger_suite",
        f"--env.suite.name={suite}",
        f"--env.task={task}",
        f"--env.suite.obs_mode={obs_mode}",
        "--env.suite.num_points=128",
        "--env.suite.image_size=32",
        "--env.suite.episode_length=30",
        "--eval.n_episodes=1",
        "--eval.batch_size=1",
        f"--output_dir={output_dir}",
        *extra,
    ]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return json.loads((output_dir / "eval_info.json").read_text())


def imitation_loss(policy: MTDAggerPolicy, preprocessor, dataset_root: Path) -> float:
    """The policy's loss (MSE to the expert actions, normalised) over every frame of the dataset."""
    dataset = LeRobotDataset("local/tiny", root=dataset_root)
    batch = next(iter(torch.utils.data.DataLoader(dataset, batch_size=len(dataset))))
    with torch.no_grad():
        return policy.forward(preprocessor(batch))[0].item()


def test_stock_lerobot_train_and_eval_on_state(tmp_path, expert_dataset_factory):
    suite = make_suite("metaworld-mt10", tasks=TASKS)
    root = expert_dataset_factory(suite)
    checkpoint = lerobot_train(root, tmp_path / "train")

    policy = MTDAggerPolicy.from_pretrained(checkpoint)
    assert policy.config.task_names == TASKS, "the vocabulary comes from the dataset and is saved"
    pre, post = make_pre_post_processors(policy.config, pretrained_path=str(checkpoint))

    # lerobot-train really trained the weights: the checkpoint imitates the experts clearly better than
    # freshly initialised policies of the same config, which predict about 0 in normalised units (a
    # loss near 1, the actions' variance). Measured: about 0.54 after 20 steps, 0.99-1.01 fresh.
    fresh_losses = []
    for seed in range(3):
        torch.manual_seed(seed)
        fresh_losses.append(imitation_loss(MTDAggerPolicy(policy.config), pre, root))
    trained_loss = imitation_loss(policy, pre, root)
    assert trained_loss < 0.8 * min(fresh_losses), f"trained {trained_loss:.3f}, fresh {fresh_losses}"

    # Identical actions through the saved processors, for two independent loads.
    env = suite.make_env("button-press-topdown-v3", seed=3)
    observation, _ = env.reset()
    env.close()
    batch = {k: torch.as_tensor(v) for k, v in observation.items()} | {"task": "button-press-topdown-v3"}
    again = MTDAggerPolicy.from_pretrained(checkpoint)
    actions = [post(p.select_action(pre(dict(batch)))) for p in (policy, again)]
    assert actions[0].shape == (1, 4)
    torch.testing.assert_close(actions[0], actions[1], rtol=0, atol=0)

    info = lerobot_eval(checkpoint, tmp_path / "eval", "state", [])
    assert info["overall"]["n_episodes"] == 1
    assert len(info["per_task"][0]["metrics"]["successes"]) == 1
    assert np.isfinite(info["overall"]["avg_sum_reward"])


@pytest.mark.slow  # rendered clouds and lerobot-eval, about 40 s
def test_stock_lerobot_eval_on_point_clouds_through_the_rename_map(tmp_path, expert_dataset_factory):
    suite = make_suite(
        "metaworld-mt10", tasks=TASKS, observation=ObservationConfig(obs_mode="pointcloud", num_points=128)
    )
    root = expert_dataset_factory(suite, episodes_per_task=1, steps=20)
    checkpoint = lerobot_train(root, tmp_path / "train", steps=4)
    config = json.loads((checkpoint / "config.json").read_text())
    assert config["input_features"]["observation.pointcloud"]["shape"] == [128, 3]
    rename = '--rename_map={"observation.environment_state": "observation.pointcloud"}'
    info = lerobot_eval(checkpoint, tmp_path / "eval", "pointcloud", [rename])
    assert info["overall"]["n_episodes"] == 1
    assert np.isfinite(info["overall"]["avg_sum_reward"])


@pytest.mark.slow
def test_stock_lerobot_train_and_eval_on_a_merged_point_cloud_experiment(tmp_path):
    """The README's route for the paper's main setting: point-cloud rounds -> D(k) -> stock tools."""
    import draccus

    from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, merge_rounds
    from lerobot_mtdagger.runner.configs import RunConfig
    from lerobot_mtdagger.runner.dagger import run

    drawers = ["drawer-bar-wide", "drawer-knob-small"]
    args = [
        "--suite.name=drawers",
        "--suite.obs_mode=pointcloud",
        f"--suite.tasks=[{','.join(drawers)}]",
        "--dagger.rounds=1",
        "--dagger.initial_demos=1",
        "--dagger.budget_per_task=1",
        "--scheduler.n_min=1",
        "--training.steps_per_round=5",
        "--rollout.eval_episodes=1",
        "--suite.num_points=64",
        "--rollout.max_steps=30",
        "--rollout.workers=0",
        "--progress=false",
        f"--output_dir={tmp_path / 'run'}",
    ]
    run(draccus.parse(RunConfig, args=args))
    experiment = ExperimentDir(tmp_path / "run")
    merged = merge_rounds(experiment, [0, 1], tmp_path / "d1", repo_id="local/d1")
    dataset = LeRobotDataset("local/d1", root=merged)
    rounds = [LeRobotDataset("local/r", root=experiment.round_root(k)) for k in (0, 1)]
    assert len(dataset) == sum(len(r) for r in rounds)
    assert dataset.num_episodes == sum(r.num_episodes for r in rounds)
    last = rounds[1][len(rounds[1]) - 1]
    torch.testing.assert_close(
        dataset[len(dataset) - 1]["observation.pointcloud"], last["observation.pointcloud"]
    )
    assert dataset[len(dataset) - 1]["task"] == last["task"]

    checkpoint = lerobot_train(merged, tmp_path / "train", steps=4, repo_id="local/d1")
    config = json.loads((checkpoint / "config.json").read_text())
    assert config["input_features"]["observation.pointcloud"]["shape"] == [64, 3]
    assert config["task_names"] == drawers
    rename = '--rename_map={"observation.environment_state": "observation.pointcloud"}'
    extra = [rename, "--env.suite.num_points=64"]
    info = lerobot_eval(checkpoint, tmp_path / "eval", "pointcloud", extra, suite="drawers", task=drawers[1])
    assert info["overall"]["n_episodes"] == 1
    assert np.isfinite(info["overall"]["avg_sum_reward"])
