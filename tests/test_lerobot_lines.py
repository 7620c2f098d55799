"""Round datasets written on one LeRobot line are read by the other (stored fixtures of each line).

``tests/data/experiment-lerobot-0.4.4`` was written with LeRobot 0.4.4 (Python 3.11) and
``experiment-lerobot-0.6.1`` with LeRobot 0.6.1 (Python 3.12); CI runs this file on both lines, so each
direction is checked: LeRobot loads every round, ``verify`` finds nothing wrong, ``merge`` makes D(k),
and a resumed run adds a round written by this line to an experiment started on the other.
"""

from __future__ import annotations

import json
import shutil
from pathlib import Path

import pytest

from lerobot_mtdagger.cli import main

DATA = Path(__file__).parent / "data"
LINES = ["0.4.4", "0.6.1"]
OPTIONS = ["--suite.name=toy", "--dagger.initial_demos=2", "--dagger.budget_per_task=2"]
OPTIONS += ["--rollout.eval_episodes=2", "--training.steps_per_round=5", "--policy.batch_size=16"]
OPTIONS += ["--policy.state_hidden_dims=[16]", "--policy.head_hidden_dims=[16]", "--rollout.workers=0"]
OPTIONS += ["--progress=false"]


@pytest.fixture(params=LINES)
def stored(request, tmp_path) -> Path:
    """A copy of the experiment one LeRobot line wrote."""
    root = tmp_path / f"written-by-{request.param}"
    shutil.copytree(DATA / f"experiment-lerobot-{request.param}", root)
    return root


def _episodes_per_round(root: Path) -> list[int]:
    return [
        json.loads((root / "rounds" / f"round-{k:03d}" / "meta" / "info.json").read_text())["total_episodes"]
        for k in range(2)
    ]


def test_lerobot_loads_the_rounds_of_either_line(stored):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    for k, episodes in enumerate(_episodes_per_round(stored)):
        root = stored / "rounds" / f"round-{k:03d}"
        dataset = LeRobotDataset(f"local/round-{k:03d}", root=root, video_backend="pyav")
        assert dataset.num_episodes == episodes
        frame = dataset[0]
        assert {"observation.state", "action", "executed_action", "learner_acted", "task"} <= set(frame)
        record = json.loads((root / "meta" / "mtdagger.json").read_text())
        assert record["round"] == k


def test_verify_and_merge_read_the_rounds_of_either_line(stored, capsys, tmp_path):
    assert main(["verify", f"--experiment_dir={stored}"]) == 0
    assert "0 problem(s)" in capsys.readouterr().out
    merged = tmp_path / "merged"
    assert main(["merge", f"--experiment_dir={stored}", f"--output={merged}"]) == 0
    info = json.loads((merged / "meta" / "info.json").read_text())
    assert info["total_episodes"] == sum(_episodes_per_round(stored))


def test_a_run_started_on_one_line_resumes_on_the_other(stored, capsys):
    before = {p: p.read_bytes() for p in (stored / "rounds").rglob("*") if p.is_file()}
    assert main(["run", *OPTIONS, "--dagger.rounds=2", f"--output_dir={stored}", "--resume=true"]) == 0
    assert "round 2:" in capsys.readouterr().out
    assert all(p.read_bytes() == data for p, data in before.items()), "earlier rounds untouched"
    assert main(["verify", f"--experiment_dir={stored}"]) == 0
