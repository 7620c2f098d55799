"""Stock ``lerobot-train`` and ``lerobot-eval`` on the ``mtdagger`` policy and our suites (subprocesses)."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

import numpy as np
import torch
from lerobot.policies.factory import make_pre_post_processors
from safetensors.torch import load_file

from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.policies import MTDAggerPolicy
from tests.conftest import lerobot_train

BIN = Path(sys.executable).parent
TASKS = ["reach-v3", "button-press-topdown-v3"]


def lerobot_eval(checkpoint: Path, output_dir: Path, obs_mode: str, extra: list[str]) -> dict:
    command = [
        str(BIN / "lerobot-eval"),
        f"--policy.path={checkpoint}",
        "--policy.device=cpu",
        "--env.discover_packages_path=lerobot_mtdagger.envs",
        "--env.type=mtdagger_suite",
        "--env.suite=metaworld-mt10",
        "--env.task=reach-v3",
        f"--env.obs_mode={obs_mode}",
        "--env.num_points=128",
        "--env.image_size=32",
        "--env.episode_length=30",
        "--eval.n_episodes=1",
        "--eval.batch_size=1",
        f"--output_dir={output_dir}",
        *extra,
    ]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return json.loads((output_dir / "eval_info.json").read_text())


def test_stock_lerobot_train_and_eval_on_state(tmp_path, expert_dataset_factory):
    suite = make_suite("metaworld-mt10", tasks=TASKS)
    root = expert_dataset_factory(suite)
    checkpoint = lerobot_train(root, tmp_path / "train")

    policy = MTDAggerPolicy.from_pretrained(checkpoint)
    assert policy.config.task_names == TASKS, "the vocabulary comes from the dataset and is saved"
    saved = load_file(checkpoint / "model.safetensors")
    for name, tensor in policy.state_dict().items():
        torch.testing.assert_close(tensor, saved[name], rtol=0, atol=0)

    # Identical actions through the saved processors, for two independent loads.
    pre, post = make_pre_post_processors(policy.config, pretrained_path=str(checkpoint))
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


def test_stock_lerobot_eval_on_point_clouds_through_the_rename_map(tmp_path, expert_dataset_factory):
    suite = make_suite("metaworld-mt10", tasks=TASKS, obs_mode="pointcloud", num_points=128)
    root = expert_dataset_factory(suite, episodes_per_task=1, steps=20)
    checkpoint = lerobot_train(root, tmp_path / "train", steps=4)
    config = json.loads((checkpoint / "config.json").read_text())
    assert config["input_features"]["observation.pointcloud"]["shape"] == [128, 3]
    rename = '--rename_map={"observation.environment_state": "observation.pointcloud"}'
    info = lerobot_eval(checkpoint, tmp_path / "eval", "pointcloud", [rename])
    assert info["overall"]["n_episodes"] == 1
    assert np.isfinite(info["overall"]["avg_sum_reward"])
