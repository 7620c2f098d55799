"""The Multitask DAgger runner end to end on real MetaWorld tasks (tiny configurations)."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
import torch

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir, merge_rounds
from lerobot_mtdagger.datasets.records import RoundRecord
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.envs.drawers.catalogue import HELDOUT_TASKS
from lerobot_mtdagger.policies import MTDAggerPolicy
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.utils.errors import UserError
from lerobot_mtdagger.utils.lerobot_compat import INFO_KEEPS_OTHER_KEYS
from tests.conftest import lerobot_train
from tests.helpers import edit_round_record, kill_9_and_check_workers_end, small_drawer_cloud_args

TASKS = ["reach-v3", "button-press-topdown-v3", "push-v3"]
TINY = [
    "--suite.tasks=[reach-v3,button-press-topdown-v3,push-v3]",
    "--dagger.rounds=2",
    "--training.steps_per_round=60",
    "--rollout.eval_episodes=1",
    "--rollout.max_steps=60",
    "--policy.batch_size=64",
    "--progress=false",
]


def tiny_config(output_dir: Path, *extra: str) -> RunConfig:
    import draccus

    return draccus.parse(RunConfig, args=[*TINY, f"--output_dir={output_dir}", *extra])


@pytest.fixture(scope="module")
def experiment(tmp_path_factory) -> ExperimentDir:
    root = tmp_path_factory.mktemp("dagger") / "need"
    lines = run(tiny_config(root, "--scheduler.type=need"))
    assert len(lines) == 3 and lines[0].startswith("round 0:")
    return ExperimentDir(root)


def test_lerobot_loads_a_round_and_its_merge_without_a_warning(experiment, tmp_path, caplog):
    """The record lives in meta/mtdagger.json; info.json mirrors it only where LeRobot keeps other keys."""
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    merged = merge_rounds(experiment, [0, 1, 2], tmp_path / "merged")
    for root in (experiment.round_root(1), merged):
        caplog.clear()
        with caplog.at_level("WARNING"):
            LeRobotDataset("local/round", root=root, video_backend="pyav")
        assert not [r.getMessage() for r in caplog.records if "Unknown fields" in r.getMessage()], root
        info = json.loads((root / "meta" / "info.json").read_text())
        record = json.loads((root / "meta" / "mtdagger.json").read_text())
        assert info["mtdagger"] == record if INFO_KEEPS_OTHER_KEYS else "mtdagger" not in info


def test_every_round_is_committed_with_its_record(experiment):
    assert experiment.committed_rounds() == [0, 1, 2]
    assert experiment.committed_phases() == [0, 1, 2]
    for k in range(3):
        record = experiment.read_round_record(k)
        stored = json.loads((experiment.round_root(k) / "meta" / "mtdagger.json").read_text())
        assert RoundRecord.from_dict(stored) == record and record.committed
        assert record.task_names == TASKS and record.round == k and record.method == "need"
        assert sum(record.episodes_per_task) == record.budget
    round0, round1, round2 = (experiment.read_round_record(k) for k in range(3))
    assert round0.episodes_per_task == [3, 3, 3] and round0.beta == 1.0
    assert round0.success_rate is None and round0.allocation is None and "round 0" in round0.notes[0]
    assert round1.success_rate is None and any("prior decides" in n for n in round1.notes)
    assert round1.episodes_per_task == [3, 3, 3], "the prior decides: uniform"
    assert round1.beta == 0.5 and round2.beta == 0.0
    assert round2.success_rate == round1.learner_success, "task need: learner-only episodes"
    assert 0 < sum(round1.learner_episodes) < sum(round1.episodes_per_task), "episode mixing at 0.5"
    assert round1.gain is None and experiment.read_phase_record(0).gain is None, "no gain from scratch"
    assert round2.gain == experiment.read_phase_record(1).gain is not None
    assert round2.eval_success == experiment.read_phase_record(1).eval["success"]
    assert round2.demos_so_far == [
        a + b for a, b in zip(round1.demos_so_far, round2.episodes_per_task, strict=True)
    ]


def test_verify_recomputes_every_allocation(experiment):
    assert verify_experiment(experiment) == (3, 3, [])


def test_verify_detects_a_tampered_round(experiment, tmp_path):
    copy = tmp_path / "copy"
    shutil.copytree(experiment.root, copy)

    def tamper(record):
        record["allocation"]["metric"][0] += 0.5
        record["episodes_per_task"] = [9, 0, 0]

    edit_round_record(copy / "rounds" / "round-002", tamper)
    _, _, problems = verify_experiment(ExperimentDir(copy))
    assert any("data holds" in p for p in problems)
    assert any("metric" in p for p in problems)
    with pytest.raises(SystemExit) as exit_:
        main(["verify", f"--experiment_dir={copy}"])
    assert exit_.value.code == 1


def test_frames_store_expert_labels_and_what_was_executed(experiment):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset("local/round-001", root=experiment.round_root(1))
    table = dataset.hf_dataset.with_format("numpy")
    learner = np.asarray(table["learner_acted"]).reshape(-1).astype(bool)
    assert learner.any() and (~learner).any(), "beta=0.5 mixes expert and learner steps"
    executed, label = np.asarray(table["executed_action"]), np.asarray(table["action"])
    np.testing.assert_array_equal(executed[~learner], label[~learner])
    assert not np.allclose(executed[learner], label[learner])
    assert set(np.asarray(table["dagger_round"]).reshape(-1).tolist()) == {1}
    assert dataset.meta.tasks.sort_values("task_index").index.tolist() == TASKS


def test_merged_rounds_load_as_one_dataset_with_the_same_task_indices(experiment, tmp_path):
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    merged_root = merge_rounds(experiment, [0, 1, 2], tmp_path / "merged")
    merged = LeRobotDataset("local/merged", root=merged_root)
    episodes = sum(sum(experiment.read_round_record(k).episodes_per_task) for k in range(3))
    assert merged.num_episodes == episodes
    assert merged.meta.tasks.sort_values("task_index").index.tolist() == TASKS
    item = merged[len(merged) - 1]
    assert TASKS[int(item["task_index"])] == item["task"]
    checkpoint = lerobot_train(merged_root, tmp_path / "train", steps=4, repo_id="local/merged")
    assert MTDAggerPolicy.from_pretrained(str(checkpoint)).config.task_names == TASKS


def test_report_gives_success_against_demos(experiment, tmp_path, capsys):
    from lerobot_mtdagger.analysis.results import learning_curves

    curves = learning_curves([experiment.root])
    assert [(p.method, p.round, p.demos_per_task, p.seeds) for p in curves][:2] == [
        ("need", 0, 3.0, 1),
        ("need", 1, 6.0, 1),
    ]
    assert curves[2].mean == experiment.read_phase_record(2).eval_mean
    with pytest.raises(ValueError, match="Two need experiments with seed 0"):
        learning_curves([experiment.root, experiment.root])
    main(["report", f"--experiments=[{experiment.root}]", f"--output={tmp_path / 'r.md'}"])
    assert "| need | 2 |" in (tmp_path / "r.md").read_text()


def test_report_refuses_to_average_runs_of_different_configs(experiment, tmp_path):
    from lerobot_mtdagger.analysis.results import learning_curves

    other = tmp_path / "need-longer"
    shutil.copytree(experiment.root, other)
    config = json.loads((other / "config.json").read_text())
    config["seed"], config["rollout"]["workers"], config["training"]["steps_per_round"] = 1, 0, 999
    (other / "config.json").write_text(json.dumps(config))
    with pytest.raises(ValueError, match=r"different configs \(training.steps_per_round: 60 vs 999\)"):
        learning_curves([experiment.root, other])


def test_report_refuses_runs_without_evaluation(tmp_path):
    from lerobot_mtdagger.analysis.results import learning_curves
    from tests.test_toy import toy_config

    run(toy_config(tmp_path / "blind", "--dagger.rounds=0", "--rollout.eval_episodes=0"))
    with pytest.raises(ValueError, match="no evaluated phase|has an evaluated phase"):
        learning_curves([tmp_path / "blind"])


def test_round_policies_are_lerobot_pretrained_models(experiment):
    policy = MTDAggerPolicy.from_pretrained(str(experiment.policy_root(2)))
    assert policy.config.task_names == TASKS
    assert (experiment.policy_root(2) / "policy_preprocessor.json").exists()


def test_output_dir_collision_is_refused_and_nothing_is_touched(experiment):
    before = sorted(p.name for p in experiment.rounds.iterdir())
    with pytest.raises(UserError, match="pass --resume=true"):
        run(tiny_config(experiment.root))
    assert sorted(p.name for p in experiment.rounds.iterdir()) == before


def test_resume_of_a_finished_run_changes_nothing(experiment):
    """No file of the experiment (rounds, records, policies, config) is rewritten; the log may grow."""

    def contents() -> dict[str, bytes]:
        files = (p for p in experiment.root.rglob("*") if p.is_file() and p.name not in (".lock", "run.log"))
        return {str(p.relative_to(experiment.root)): p.read_bytes() for p in files}

    before = contents()
    run(tiny_config(experiment.root, "--scheduler.type=need", "--resume=true"))
    after = contents()
    assert after.keys() == before.keys() and all(after[name] == before[name] for name in before)


def test_resume_with_another_config_is_refused(experiment):
    with pytest.raises(ValueError, match="Cannot resume .* different config"):
        run(tiny_config(experiment.root, "--scheduler.type=gain", "--resume=true"))


@pytest.mark.parametrize(
    ("args", "error", "match"),
    [
        (["--suite.name=robosuite"], ValueError, "Unknown suite"),
        (["--suite.tasks=[reach-v3,jump-v3]"], ValueError, "not in metaworld-mt10"),
        (["--dagger.budget=2"], ValueError, r"budget=2 is smaller than n_min \* num_tasks = 1 \* 3 = 3"),
    ],
)
def test_bad_runs_are_refused_before_anything_is_written(tmp_path, args, error, match):
    with pytest.raises(error, match=match):
        run(tiny_config(tmp_path / "out", *args))
    assert not (tmp_path / "out").exists()


def test_unknown_method_and_missing_output_dir_are_clear_cli_errors(capsys, tmp_path):
    assert main(["run", "--scheduler.type=greedy", f"--output_dir={tmp_path}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()  # argparse's message only, without its usage
    assert len(err) == 1 and "invalid choice: 'greedy'" in err[0] and "run --help" in err[0]
    assert main(["run", "--dagger.rounds=-1"]) == 2
    assert "rounds must be >= 0, got -1" in capsys.readouterr().err


def test_foreign_dataset_in_the_output_dir_is_refused(tmp_path):
    root = tmp_path / "exp"
    (root / "rounds" / "round-000" / "meta").mkdir(parents=True)
    (root / "rounds" / "round-000" / "meta" / "info.json").write_text(
        json.dumps({"codebase_version": "v3.0"})
    )
    (root / "config.json").write_text(json.dumps(tiny_config(root).to_dict()))
    with pytest.raises(ValueError, match="is not a lerobot-mtdagger round"):
        run(tiny_config(root, "--resume=true"))
    assert (root / "rounds" / "round-000" / "meta" / "info.json").exists()


@pytest.mark.slow
def test_drawer_suite_runs_with_point_clouds_and_evaluates_the_unseen_drawers(tmp_path):
    import draccus

    args = small_drawer_cloud_args(tmp_path / "drawers")
    run(draccus.parse(RunConfig, args=args))
    experiment = ExperimentDir(tmp_path / "drawers")
    assert experiment.committed_rounds() == [0, 1]
    assert verify_experiment(experiment) == (2, 2, [])
    record = experiment.read_round_record(1)
    assert record.task_names == ["drawer-bar-wide", "drawer-lip-shallow"]
    from lerobot.datasets.lerobot_dataset import LeRobotDataset

    dataset = LeRobotDataset("local/drawers", root=experiment.round_root(1))
    assert tuple(dataset[0]["observation.pointcloud"].shape) == (128, 3)

    # Every phase is also evaluated on the unseen drawers (task dropout gives the policy a shared
    # embedding to act on them), beside the training drawers' success and never given to the scheduler.
    for phase in (0, 1):
        record = experiment.read_phase_record(phase)
        assert record.heldout_eval["task_names"] == list(HELDOUT_TASKS)
        assert record.heldout_eval["episodes"] == [1] * len(HELDOUT_TASKS)
        assert all(0 <= p <= 3 for p in record.heldout_eval["progress"] + record.eval["progress"])
    assert experiment.read_round_record(1).episodes_per_task == [1, 1]

    from lerobot_mtdagger.commands.configs.eval import EvalConfig
    from lerobot_mtdagger.commands.eval import eval_command

    policy = experiment.policy_root(1)
    # No --suite.obs_mode / --suite.num_points: eval reads them from the policy's inputs (a 128-point cloud).
    args = [
        f"--policy_path={policy}",
        "--suite.name=drawers",
        "--suite.tasks=[heldout]",
        "--suite.placement=kitchen",
    ]
    result = eval_command(draccus.parse(EvalConfig, args=[*args, "--episodes=1", "--workers=0"]))
    assert result["task_names"] == list(HELDOUT_TASKS) and len(result["progress"]) == len(HELDOUT_TASKS)

    # report carries them: the in-domain / unseen table and the unseen-success figure.
    from lerobot_mtdagger.analysis.results import results_rows
    from lerobot_mtdagger.analysis.summary import write_report

    rows = results_rows([experiment.root])
    assert [row["unseen_tasks"] for row in rows] == [list(HELDOUT_TASKS)] * 2
    task_names = experiment.read_round_record(0).task_names
    markdown = write_report(rows, task_names, tmp_path / "report").read_text()
    assert "## In-domain and unseen tasks" in markdown
    assert (tmp_path / "report" / "unseen_success_vs_demos.png").stat().st_size > 0


def _cli(output_dir: Path, *extra: str) -> list[str]:
    return [
        str(Path(sys.executable).parent / "lerobot-mtdagger"),
        "run",
        *TINY,
        "--rollout.workers=2",
        f"--output_dir={output_dir}",
        *extra,
    ]


def _allocations(root: Path) -> list:
    experiment = ExperimentDir(root)
    return [
        (r.episodes_per_task, r.metric, r.rollout_success, r.eval_success)
        for r in (experiment.read_round_record(k) for k in experiment.committed_rounds())
    ]


@pytest.mark.parametrize(
    "kill_when",
    [
        # MetaWorld's kills run with the slow set (the kill campaign hits 20 moments of this run);
        # tests/test_toy.py kills a toy run with two env workers in the default suite.
        pytest.param("policies/.staging/round-001", marks=pytest.mark.slow),  # training phase 1
        pytest.param("policies/round-000/training.json", marks=pytest.mark.slow),  # round-1 collection
        pytest.param("policies/.staging/round-001/model.safetensors", marks=pytest.mark.slow),  # eval
        pytest.param("rounds/round-001", marks=pytest.mark.slow),  # right after round 1's commit
    ],
)
def test_kill_9_and_resume_gives_the_same_allocations(tmp_path, kill_when):
    reference = tmp_path / "reference"
    subprocess.run(_cli(reference, "--scheduler.type=need"), check=True, capture_output=True)
    killed = tmp_path / "killed"
    process = subprocess.Popen(
        _cli(killed, "--scheduler.type=need"), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL
    )
    deadline = time.time() + 300
    while not (killed / kill_when).exists() and process.poll() is None and time.time() < deadline:
        time.sleep(0.05)
    assert process.poll() is None, "the run finished before it could be killed"
    kill_9_and_check_workers_end(process, workers=2)
    subprocess.run(_cli(killed, "--scheduler.type=need", "--resume=true"), check=True, capture_output=True)
    assert _allocations(killed) == _allocations(reference)
    assert verify_experiment(ExperimentDir(killed)) == (3, 3, [])
    for k in range(3):
        weights = [
            MTDAggerPolicy.from_pretrained(str(ExperimentDir(r).policy_root(k))).state_dict()
            for r in (reference, killed)
        ]
        for name, tensor in weights[0].items():
            torch.testing.assert_close(tensor, weights[1][name], rtol=0, atol=0)


@pytest.mark.slow
def test_dagger_improves_a_weak_bc_policy(tmp_path):
    """One demo per task gives a weak BC policy; three DAgger rounds lift it on the same eval seeds."""
    import draccus

    config = draccus.parse(
        RunConfig,
        args=[
            "--suite.tasks=[reach-v3,push-v3,pick-place-v3,peg-insert-side-v3]",
            "--dagger.initial_demos=1",
            "--dagger.rounds=3",
            "--dagger.budget_per_task=5",
            "--training.steps_per_round=2000",
            "--rollout.eval_episodes=10",
            "--progress=false",
            f"--output_dir={tmp_path / 'run'}",
        ],
    )
    run(config)
    experiment = ExperimentDir(tmp_path / "run")
    means = [experiment.read_phase_record(k).eval_mean for k in range(4)]
    assert means[-1] >= means[0] + 0.15, means
