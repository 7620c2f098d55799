"""Shared test factories, and one torch thread per pytest-xdist worker."""

from __future__ import annotations

import logging
import os
import subprocess
import sys
from pathlib import Path

import pytest


def pytest_configure(config: pytest.Config) -> None:
    """Gives each pytest-xdist worker, and the runs it starts, one thread.

    The workers take every core; two threads per process beside another busy one trained many times
    slower (``analysis.compare.run_resources``). ``-n 0`` keeps torch's default.
    """
    del config
    if os.environ.get("PYTEST_XDIST_WORKER") is None:
        return
    os.environ["OMP_NUM_THREADS"] = os.environ["MKL_NUM_THREADS"] = "1"
    import torch

    torch.set_num_threads(1)


def record_expert_dataset(
    root: Path, suite, episodes_per_task: int = 2, steps: int = 40, repo_id: str = "local/tiny"
):
    """Records expert episodes of every task of ``suite`` into a new LeRobotDataset at ``root``.

    The task vocabulary is fixed to ``suite.task_names`` right after creation, so task_index i is
    ``suite.task_names[i]``.
    """
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    from lerobot_mtdagger.experts import make_expert

    dataset = LeRobotDataset.create(
        repo_id=repo_id, fps=80, features=suite.features, root=root, use_videos=False
    )
    dataset.meta.save_episode_tasks(suite.task_names)
    for task_name in suite.task_names:
        env, expert = suite.make_env(task_name), make_expert(suite, task_name)
        for seed in range(episodes_per_task):
            observation, info = env.reset(seed=seed)
            expert.reset()
            for _ in range(steps):
                action = expert.act(info["privileged_state"])
                dataset.add_frame({**observation, "action": action, "task": task_name})
                observation, _, _, _, info = env.step(action)
            dataset.save_episode()
        env.close()
    dataset.finalize()
    return dataset


@pytest.fixture
def expert_dataset_factory(tmp_path):
    """Builds small expert datasets under the test's tmp dir: ``factory(suite, name) -> root``."""

    def factory(suite, name: str = "dataset", **kwargs) -> Path:
        root = tmp_path / name
        record_expert_dataset(root, suite, **kwargs)
        return root

    return factory


def eval_freq_option() -> str:
    """Stock ``lerobot-train``'s option that turns evaluation off: ``--eval_freq`` on LeRobot 0.4,
    ``--env_eval_freq`` from 0.5 on (the field was renamed)."""
    import dataclasses

    from lerobot.configs.train import TrainPipelineConfig

    names = {field.name for field in dataclasses.fields(TrainPipelineConfig)}
    return "--env_eval_freq=0" if "env_eval_freq" in names else "--eval_freq=0"


def lerobot_train(dataset_root: Path, output_dir: Path, steps: int = 20, repo_id: str = "local/tiny") -> Path:
    """Runs stock ``lerobot-train`` on a local dataset; returns the last checkpoint's model folder."""
    command = [
        str(Path(sys.executable).parent / "lerobot-train"),
        "--policy.type=mtdagger",
        "--policy.discover_packages_path=lerobot_mtdagger.policies",
        "--policy.device=cpu",
        "--policy.push_to_hub=false",
        f"--dataset.repo_id={repo_id}",
        f"--dataset.root={dataset_root}",
        f"--steps={steps}",
        "--batch_size=16",
        "--num_workers=0",
        f"--save_freq={steps}",
        eval_freq_option(),
        "--wandb.enable=false",
        f"--output_dir={output_dir}",
    ]
    subprocess.run(command, check=True, capture_output=True, text=True)
    return output_dir / "checkpoints" / "last" / "pretrained_model"


class RecordsHandler(logging.Handler):
    """Collects the formatted messages it handles."""

    def __init__(self) -> None:
        super().__init__(level=logging.DEBUG)
        self.messages: list[str] = []

    def emit(self, record: logging.LogRecord) -> None:
        self.messages.append(f"{record.name}: {record.getMessage()}")


@pytest.fixture
def root_records():
    """A handler on the root logger at INFO for the test; root's level and handlers are restored."""
    root = logging.getLogger()
    handler, level = RecordsHandler(), root.level
    root.addHandler(handler)
    root.setLevel(logging.INFO)
    yield handler
    root.removeHandler(handler)
    root.setLevel(level)
