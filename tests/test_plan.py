"""``lerobot-mtdagger plan``: the next session's episodes per task from LeRobot datasets (``planning/``).

The datasets are built with LeRobot's own recording API (``LeRobotDataset.create``, ``add_frame``,
``save_episode``), as ``lerobot-record`` and ``lerobot-rollout`` write them, on whichever LeRobot line
runs the tests: a per-frame ``next.success`` and, for DAgger sessions, an ``intervention`` column.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.planning.episodes import open_metadata
from lerobot_mtdagger.scheduler import KalmanSuccessEstimator
from lerobot_mtdagger.utils.errors import UserError

FIXTURE_ROUND = Path(__file__).parent / "data" / "experiment-lerobot-0.4.4" / "rounds" / "round-001"


def record(root: Path, episodes: list[tuple[str, bool, bool]], success: bool = True, fps: int = 10) -> Path:
    """A LeRobot dataset of ``(task, success, intervened)`` episodes of 5 frames, via LeRobot's API."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    features = {
        "observation.state": {"dtype": "float32", "shape": (2,), "names": None},
        "action": {"dtype": "float32", "shape": (2,), "names": None},
        "intervention": {"dtype": "bool", "shape": (1,), "names": None},
    }
    if success:
        features["next.success"] = {"dtype": "bool", "shape": (1,), "names": None}
    dataset = LeRobotDataset.create(
        f"local/{root.name}", fps=fps, features=features, root=root, use_videos=False
    )
    for task, succeeded, intervened in episodes:
        for step in range(5):
            frame = {
                "observation.state": np.full(2, step, np.float32),
                "action": np.zeros(2, np.float32),
                "intervention": np.array([intervened and step == 2]),
                "task": task,
            }
            if success:
                frame["next.success"] = np.array([succeeded and step == 4])
            dataset.add_frame(frame)
        dataset.save_episode()
    dataset.finalize()
    return root


# session 1: pick succeeds 3/3; place 1/3 on its own, and once more only because a person took over
SESSION_1 = [("pick", True, False)] * 3 + [("place", True, False), ("place", False, False)] * 1
SESSION_1 += [("place", False, False), ("place", True, True)]
SESSION_2 = [("pick", True, False), ("pick", False, False), ("place", True, False), ("place", True, False)]


def plan(tmp_path: Path, name: str, *options: str) -> tuple[int, dict | None]:
    out = tmp_path / f"{name}.json"
    status = main(["plan", *options, f"--output={out}"])
    return status, (json.loads(out.read_text()) if out.exists() else None)


def test_a_plan_counts_the_policys_own_episodes_and_gives_the_weaker_task_more(tmp_path, capsys):
    data = record(tmp_path / "session-1", SESSION_1)
    status, first = plan(tmp_path, "plan-1", f"--datasets=[{data}]", "--budget=20")
    assert status == 0
    assert first["tasks"] == ["pick", "place"]
    measured = first["measurements"]
    # the intervened place episode is read but not counted as the policy's success
    assert measured["episodes"] == [3, 4] and measured["policy_episodes"] == [3, 3]
    assert measured["successes"] == [3, 1]
    kalman = KalmanSuccessEstimator(2)
    kalman.update([1.0, 1 / 3], [3, 3])
    np.testing.assert_allclose(first["allocation"]["kalman_posterior"]["p"], kalman.p)
    counts = first["allocation"]["episodes_per_task"]
    assert sum(counts) == 20 and counts[1] > counts[0] >= 1
    source = first["inputs"][0]
    assert (
        source["root"] == str(data) and len(source["checksum"]) == 64 and source["episodes"] == list(range(7))
    )
    assert source["policy_only"] == [True] * 6 + [False] and source["success_key"] == "frames:next.success"
    table = capsys.readouterr().out
    assert "| place | 4 | 3 | 0.33 |" in table and f"plan file: {tmp_path / 'plan-1.json'}" in table
    assert main(["plan", f"--verify={tmp_path / 'plan-1.json'}"]) == 0


def test_the_next_plan_continues_the_kalman_filters_of_the_previous_one(tmp_path, capsys):
    first_data = record(tmp_path / "session-1", SESSION_1)
    second_data = record(tmp_path / "session-2", SESSION_2)
    assert plan(tmp_path, "plan-1", f"--datasets=[{first_data}]", "--budget=20")[0] == 0
    previous = tmp_path / "plan-1.json"
    status, second = plan(
        tmp_path, "plan-2", f"--datasets=[{second_data}]", "--budget=20", f"--previous={previous}"
    )
    assert status == 0 and second["session"] == 1
    first = json.loads(previous.read_text())
    assert second["state_before"] == first["state"]
    kalman = KalmanSuccessEstimator(2)
    kalman.update([1.0, 1 / 3], [3, 3])
    kalman.update([0.5, 1.0], [2, 2])
    np.testing.assert_allclose(second["allocation"]["kalman_posterior"]["p"], kalman.p)
    assert second["previous"]["sha256"] and second["measurements"]["successes"] == [1, 2]
    assert main(["plan", f"--verify={tmp_path / 'plan-2.json'}"]) == 0
    capsys.readouterr()


def test_verify_names_an_edited_plan_a_changed_dataset_and_a_changed_previous_plan(tmp_path, capsys):
    first_data = record(tmp_path / "session-1", SESSION_1)
    second_data = record(tmp_path / "session-2", SESSION_2)
    plan(tmp_path, "plan-1", f"--datasets=[{first_data}]", "--budget=20")
    plan(
        tmp_path,
        "plan-2",
        f"--datasets=[{second_data}]",
        "--budget=20",
        f"--previous={tmp_path / 'plan-1.json'}",
    )
    second = tmp_path / "plan-2.json"
    pristine = second.read_text()

    def problems() -> str:
        capsys.readouterr()
        with pytest.raises(SystemExit) as exited:
            main(["plan", f"--verify={second}"])
        assert exited.value.code == 1
        return capsys.readouterr().out

    edited = json.loads(pristine)
    edited["allocation"]["episodes_per_task"] = [10, 10]
    second.write_text(json.dumps(edited))
    assert "allocation: recorded [10, 10] != recomputed" in problems()
    edited = json.loads(pristine)
    edited["inputs"][0]["success"][1] = True  # the pick failure recorded as a success
    second.write_text(json.dumps(edited))
    assert "measurements.successes: recorded [1, 2] != recomputed" in problems()
    second.write_text(pristine)
    first = tmp_path / "plan-1.json"
    first.write_text(first.read_text().replace('"budget": 20', '"budget": 21', 1))
    assert "previous plan" in problems() and "changed since this plan read it" in problems()
    info = second_data / "meta" / "info.json"
    info.write_text(info.read_text() + "\n")
    assert f"dataset {second_data}: its files changed since the plan" in problems()


def test_a_budget_in_operator_minutes_fits_the_episodes_into_it(tmp_path, capsys):
    data = record(tmp_path / "session-1", SESSION_1)
    status, made = plan(
        tmp_path, "plan", f"--datasets=[{data}]", "--budget_minutes=10", "--episode_seconds=45"
    )
    assert status == 0
    assert made["budget"]["episodes"] == 13 and made["budget"]["minutes"] == pytest.approx(13 * 0.75)
    # measured durations: 5 frames at 10 fps = 0.5 s an episode
    status, measured = plan(tmp_path, "measured", f"--datasets=[{data}]", "--budget_minutes=0.2")
    assert status == 0 and measured["measurements"]["episode_seconds"] == [0.5, 0.5]
    assert measured["budget"]["episodes"] == 24


def test_a_runs_rounds_are_read_as_policy_episodes_with_their_interventions(tmp_path):
    status, made = plan(
        tmp_path, "plan", f"--datasets=[{FIXTURE_ROUND}]", "--budget=6", "--scheduler.type=need_raw"
    )
    assert status == 0 and made["tasks"] == ["toy-left", "toy-right", "toy-up-windy"]
    assert made["measurements"]["episodes"] == [2, 2, 2] and made["allocation"]["method"] == "need_raw"
    status, by_episode = plan(
        tmp_path, "by-episode", f"--datasets=[{FIXTURE_ROUND}]", "--budget=6", "--success_key=success"
    )
    assert status == 0 and by_episode["inputs"][0]["success_key"] == "episodes:success"
    assert by_episode["measurements"]["successes"] == made["measurements"]["successes"]


def _refused(tmp_path, capsys, *options: str) -> str:
    out = tmp_path / "refused.json"
    capsys.readouterr()  # what recording the datasets printed
    assert main(["plan", *options, f"--output={out}"]) == 2
    error = capsys.readouterr().err
    assert len(error.strip().splitlines()) == 1 and not out.exists()
    return error


def test_bad_input_is_refused_in_one_line_and_writes_nothing(tmp_path, capsys):
    data = record(tmp_path / "session-1", SESSION_1)
    silent = record(tmp_path / "no-success", [("pick", True, False), ("place", True, False)], success=False)
    assert "has no success signal: no column 'next.success' (frames) or 'success' (episodes)" in _refused(
        tmp_path, capsys, f"--datasets=[{silent}]", "--budget=5"
    )
    assert "--success_key" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget=5", "--success_key=done"
    )
    assert "No episodes of stack in the datasets" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget=5", "--tasks=[pick,place,stack]"
    )
    assert "not a task of --tasks (pick)" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget=5", "--tasks=[pick]"
    )
    assert "is not a LeRobot dataset (no meta/info.json)" in _refused(
        tmp_path, capsys, f"--datasets=[{tmp_path}]", "--budget=5"
    )
    assert "Give one budget" in _refused(tmp_path, capsys, f"--datasets=[{data}]")
    assert "does not cover n_min=1 episode(s) per task" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget_minutes=0.01"
    )
    not_a_plan = tmp_path / "notes.json"
    not_a_plan.write_text("{}")
    assert "is not a plan file" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget=5", f"--previous={not_a_plan}"
    )


def test_a_plan_from_another_task_set_and_an_existing_output_are_refused(tmp_path, capsys):
    data = record(tmp_path / "session-1", SESSION_1)
    other = record(tmp_path / "other", [("open", True, False), ("close", False, False)])
    assert plan(tmp_path, "plan-1", f"--datasets=[{data}]", "--budget=5")[0] == 0
    error = _refused(
        tmp_path, capsys, f"--datasets=[{other}]", "--budget=5", f"--previous={tmp_path / 'plan-1.json'}"
    )
    assert "have episodes of close, open, not a task of the previous plan" in error
    existing = (tmp_path / "plan-1.json").read_text()
    assert main(["plan", f"--datasets=[{data}]", "--budget=5", f"--output={tmp_path / 'plan-1.json'}"]) == 2
    assert "exists: plans are never overwritten" in capsys.readouterr().err
    assert (tmp_path / "plan-1.json").read_text() == existing


def test_a_dataset_without_task_labels_is_refused(tmp_path, capsys):
    data = record(tmp_path / "unlabelled", [("", True, False), ("", False, False)])
    assert "has no task labels" in _refused(tmp_path, capsys, f"--datasets=[{data}]", "--budget=5")


def test_operator_labels_give_success_to_a_rollout_that_records_none(tmp_path, capsys):
    rollouts = record(
        tmp_path / "rollouts", [("pick", True, False), ("place", True, False)] * 2, success=False
    )
    labels = tmp_path / "labels.json"
    labels.write_text(json.dumps({str(rollouts): {"0": True, "1": False, "2": True, "3": False}}))
    status, made = plan(
        tmp_path, "plan", f"--datasets=[{rollouts}]", "--budget=8", f"--success_labels={labels}"
    )
    assert status == 0 and made["measurements"]["successes"] == [2, 0]
    assert made["inputs"][0]["success_key"] == "labels:--success_labels"
    assert made["options"]["success_labels"]["sha256"]
    assert main(["plan", f"--verify={tmp_path / 'plan.json'}"]) == 0
    labels.write_text(json.dumps({str(rollouts): {"0": True, "1": True, "2": True, "3": True}}))
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["plan", f"--verify={tmp_path / 'plan.json'}"])
    assert f"success labels {labels} changed since the plan" in capsys.readouterr().out
    labels.write_text(json.dumps({str(rollouts): {"0": True}}))
    assert "no label for episode(s) [1, 2, 3]" in _refused(
        tmp_path, capsys, f"--datasets=[{rollouts}]", "--budget=8", f"--success_labels={labels}"
    )
    labels.write_text(json.dumps({"other/dataset": {"0": True}}))
    assert "labels other/dataset, not one of --datasets" in _refused(
        tmp_path, capsys, f"--datasets=[{rollouts}]", "--budget=8", f"--success_labels={labels}"
    )
    labels.write_text(json.dumps({str(rollouts): {"0": "yes"}}))
    assert "is not {dataset: {episode: true|false}} JSON" in _refused(
        tmp_path, capsys, f"--datasets=[{rollouts}]", "--budget=8", f"--success_labels={labels}"
    )


@pytest.mark.parametrize("line", ["0.4.4", "0.6.1"])
def test_the_gain_is_the_loss_drop_the_runner_measured_for_the_same_policies_and_data(tmp_path, capsys, line):
    """A run's two phases, read by plan as a user's policies and datasets, give the run's own losses."""
    experiment = Path(__file__).parent / "data" / f"experiment-lerobot-{line}"
    rounds = [experiment / "rounds" / name for name in ("round-000", "round-001")]
    options = [
        f"--datasets=[{rounds[1]}]",
        f"--loss_datasets=[{rounds[0]},{rounds[1]}]",
        f"--policy_path={experiment / 'policies' / 'round-001'}",
        f"--previous_policy_path={experiment / 'policies' / 'round-000'}",
        "--scheduler.type=gain",
        "--budget=9",
    ]
    status, made = plan(tmp_path, "gain", *options)
    assert status == 0
    phase = json.loads((experiment / "policies" / "round-001" / "training.json").read_text())
    np.testing.assert_allclose(made["gain"]["loss"], phase["loss_end"], rtol=1e-5)
    np.testing.assert_allclose(made["gain"]["loss_previous"], phase["loss_previous"], rtol=1e-5)
    assert made["gain"]["frames"] == phase["loss_samples"]
    drops = np.maximum(np.array(phase["loss_previous"]) - np.array(phase["loss_end"]), 0)
    np.testing.assert_allclose(made["allocation"]["gain"], drops, rtol=1e-4)
    counts = made["allocation"]["episodes_per_task"]
    assert counts[int(np.argmax(drops))] == max(counts)  # the task that improved most gets the most
    assert main(["plan", f"--verify={tmp_path / 'gain.json'}"]) == 0
    edited = json.loads((tmp_path / "gain.json").read_text())
    edited["gain"]["loss"][0] = 0.0  # as if the new policy had fitted the first task perfectly
    (tmp_path / "gain.json").write_text(json.dumps(edited))
    capsys.readouterr()
    with pytest.raises(SystemExit):
        main(["plan", f"--verify={tmp_path / 'gain.json'}"])
    assert "gain: recorded" in capsys.readouterr().out


def test_the_gain_needs_both_policies(tmp_path, capsys):
    data = record(tmp_path / "session-1", SESSION_1)
    assert "needs each task's loss drop" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget=5", "--scheduler.type=gain"
    )
    assert "give --policy_path (trained since the last session) and --previous_policy_path" in _refused(
        tmp_path, capsys, f"--datasets=[{data}]", "--budget=5", f"--policy_path={tmp_path}"
    )


def test_a_hub_repo_id_is_read_from_lerobots_cache_with_its_revision(tmp_path, monkeypatch, capsys):
    """A local stand-in for the Hub (no network here): the repo id resolves under LeRobot's home."""
    import importlib

    home = tmp_path / "lerobot-home"
    record(home / "me" / "rollouts", SESSION_1)
    for module in ("lerobot.datasets.dataset_metadata", "lerobot.datasets.lerobot_dataset"):
        try:
            loaded = importlib.import_module(module)
        except ImportError:  # LeRobot 0.4 has no dataset_metadata module
            continue
        if hasattr(loaded, "HF_LEROBOT_HOME"):
            monkeypatch.setattr(loaded, "HF_LEROBOT_HOME", home)
    # `plan` looks its inputs up (utils.hub) before LeRobot loads: from the environment variable
    monkeypatch.setenv("HF_LEROBOT_HOME", str(home))
    status, made = plan(tmp_path, "hub", "--datasets=[me/rollouts]", "--budget=10")
    assert status == 0 and made["inputs"][0]["source"] == "me/rollouts"
    assert (
        made["inputs"][0]["root"] == str(home / "me" / "rollouts") and made["inputs"][0]["revision"] == "v3.0"
    )
    assert made["measurements"]["successes"] == [3, 1]
    assert main(["plan", f"--verify={tmp_path / 'hub.json'}"]) == 0
    assert "neither a folder nor a Hub repo id" in _refused(
        tmp_path, capsys, "--datasets=[not-a-repo]", "--budget=5"
    )


def test_a_repo_id_lerobot_cannot_fetch_is_one_line(tmp_path, monkeypatch):
    """As ``plan --verify`` re-reads a recorded Hub dataset: a Hub out of reach (here a closed local port)
    is one ``UserError`` with huggingface_hub 0.x (requests) and 1.x (httpx) alike."""
    import importlib
    import socket

    import huggingface_hub.constants

    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        port = probe.getsockname()[1]
    monkeypatch.setattr(huggingface_hub.constants, "ENDPOINT", f"http://127.0.0.1:{port}")
    monkeypatch.setattr(huggingface_hub.constants, "HF_HUB_OFFLINE", False)
    for module in ("lerobot.datasets.dataset_metadata", "lerobot.datasets.lerobot_dataset"):
        try:
            loaded = importlib.import_module(module)
        except ImportError:  # LeRobot 0.4 has no dataset_metadata module
            continue
        if hasattr(loaded, "HF_LEROBOT_HOME"):
            monkeypatch.setattr(loaded, "HF_LEROBOT_HOME", tmp_path / "empty-home")
    with pytest.raises(UserError, match="cannot open me/rollouts from the Hub or LeRobot's cache"):
        open_metadata("me/rollouts")


def test_the_curve_scheduler_plans_from_the_demos_each_session_adds(tmp_path, capsys):
    first_data = record(tmp_path / "session-1", SESSION_1)
    second_data = record(tmp_path / "session-2", SESSION_2)
    options = ["--scheduler.type=curve", "--budget=20"]
    status, first = plan(tmp_path, "plan-1", f"--datasets=[{first_data}]", *options, "--initial_demos=3")
    assert status == 0 and first["demos"] == [3.0, 3.0]
    counts = first["allocation"]["episodes_per_task"]
    assert sum(counts) == 20 and first["allocation"]["history"]["demos"] == [[3.0, 3.0]]
    assert "headroom: not yet" in capsys.readouterr().out  # one session: no curve yet
    previous = tmp_path / "plan-1.json"
    status, second = plan(
        tmp_path, "plan-2", f"--datasets=[{second_data}]", *options, f"--previous={previous}"
    )
    assert status == 0
    assert second["demos"] == [3.0 + counts[0], 3.0 + counts[1]]
    assert second["allocation"]["history"]["success"] == [[1.0, 1 / 3], [0.5, 1.0]]
    assert "headroom at" in capsys.readouterr().out  # two sessions: a curve per task
    assert main(["plan", f"--verify={tmp_path / 'plan-2.json'}"]) == 0
    capsys.readouterr()


def test_the_curve_scheduler_needs_the_first_sessions_demos(tmp_path, capsys):
    data = record(tmp_path / "session-1", SESSION_1)
    status, written = plan(
        tmp_path, "plan-1", f"--datasets=[{data}]", "--scheduler.type=curve", "--budget=20"
    )
    assert status == 2 and written is None
    assert "give --initial_demos" in capsys.readouterr().err
