"""Reliability of experiment folders: one writer at a time, policy folders that cannot run code,
verify that reads the data, options checked before anything is written, one-line user errors."""

from __future__ import annotations

import copy
import json
import os
import shutil
import signal
import subprocess
import sys
from pathlib import Path

import pytest
from safetensors import safe_open
from safetensors.torch import load_file, save_file

from lerobot_mtdagger.cli import main
from lerobot_mtdagger.datasets import experiment_dir as rounds_module
from lerobot_mtdagger.datasets.checkpoints import UntrustedCheckpointError
from lerobot_mtdagger.datasets.experiment_dir import LOCK_FILE, ExperimentDir, ExperimentLockedError
from lerobot_mtdagger.datasets.verify import verify_experiment
from lerobot_mtdagger.runner import dagger as dagger_module
from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.runner.dagger import run
from lerobot_mtdagger.runner.option_groups import TrainingConfig
from lerobot_mtdagger.runner.rollout.evaluate import PolicyRunner
from lerobot_mtdagger.utils.errors import CorruptExperimentError, UserError
from tests.helpers import edit_round_record
from tests.test_toy import TOY_RUN, toy_config


@pytest.fixture(scope="module")
def finished(tmp_path_factory):
    root = tmp_path_factory.mktemp("lock") / "toy"
    run(toy_config(root, "--dagger.rounds=1"))
    return root


def test_a_second_writer_is_refused_at_once_naming_the_folder_and_the_process(finished):
    before = sorted(p.relative_to(finished) for p in finished.rglob("*"))
    expected = rf"{finished} is being written by .*pid {os.getpid()}"
    with ExperimentDir(finished).writer_lock(), pytest.raises(ExperimentLockedError, match=expected):
        run(toy_config(finished, "--dagger.rounds=1", "--resume=true"))
    assert sorted(p.relative_to(finished) for p in finished.rglob("*")) == before
    assert run(toy_config(finished, "--dagger.rounds=1", "--resume=true")), "the lock is released on exit"


def test_a_killed_writer_leaves_no_stale_lock(finished):
    code = (
        "import sys, time\n"
        "from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir\n"
        f"with ExperimentDir({str(finished)!r}).writer_lock():\n"
        "    print('locked', flush=True)\n"
        "    time.sleep(60)\n"
    )
    holder = subprocess.Popen([sys.executable, "-c", code], stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "locked"
        assert (finished / LOCK_FILE).read_text() == str(holder.pid)
        second_writer = ExperimentDir(finished).writer_lock()
        with pytest.raises(ExperimentLockedError, match=f"pid {holder.pid}"), second_writer:
            pass
    finally:
        holder.send_signal(signal.SIGKILL)
        holder.wait()
    with ExperimentDir(finished).writer_lock():
        assert (finished / LOCK_FILE).read_text() == str(os.getpid())


def hostile_copy(finished, tmp_path, step):
    folder = tmp_path / "policy"
    shutil.copytree(ExperimentDir(finished).policy_root(1), folder)
    path = folder / "policy_preprocessor.json"
    config = json.loads(path.read_text())
    config["steps"].insert(0, step)
    path.write_text(json.dumps(config))
    return folder


def test_a_policy_folder_naming_a_class_is_refused_before_anything_runs(finished, tmp_path):
    marker = tmp_path / "ran"
    step = {"class": "os.system", "config": {"command": f"touch {marker}"}}
    folder = hostile_copy(finished, tmp_path, step)
    expected = r"Step 0 of .*policy_preprocessor.json names the Python class 'os.system'.*--trust_checkpoint"
    with pytest.raises(UntrustedCheckpointError, match=expected):
        PolicyRunner.from_pretrained(folder)
    assert not marker.exists()


def test_a_policy_folder_naming_an_unregistered_step_is_refused(finished, tmp_path):
    folder = hostile_copy(finished, tmp_path, {"registry_name": "made_up_step", "config": {}})
    with pytest.raises(UntrustedCheckpointError, match="'made_up_step', which is not a registered"):
        PolicyRunner.from_pretrained(folder)


def test_the_runs_own_policies_load_without_trust(finished):
    runner = PolicyRunner.from_pretrained(ExperimentDir(finished).policy_root(1))
    assert runner.policy.config.task_names


# -------------------------------------------------------------------------------------------------
# verify reads the data (item 1)
# -------------------------------------------------------------------------------------------------


def damaged_copy(finished, tmp_path, damage) -> Path:
    """A copy of the finished experiment with ``damage(copy)`` applied."""
    copy = tmp_path / "damaged"
    shutil.copytree(finished, copy, ignore=shutil.ignore_patterns(LOCK_FILE))
    damage(copy)
    return copy


def round_parquet(root: Path, round_index: int = 1) -> Path:
    return next((ExperimentDir(root).round_root(round_index) / "data").rglob("*.parquet"))


def truncate(path: Path) -> None:
    path.write_bytes(path.read_bytes()[: len(path.read_bytes()) // 2])


def garble(path: Path) -> None:
    data = bytearray(path.read_bytes())
    middle = len(data) // 2
    data[middle : middle + 64] = bytes(64)
    path.write_bytes(bytes(data))


def nudge_weights(root: Path) -> None:
    """Changes one weight of a committed policy by 1e-3: the file still loads, only its checksum differs."""
    path = ExperimentDir(root).policy_root(1) / "model.safetensors"
    with safe_open(str(path), framework="pt") as handle:
        metadata = handle.metadata()
    tensors = load_file(path)
    name = sorted(tensors)[0]
    tensors[name] = tensors[name] + 1e-3
    save_file(tensors, str(path), metadata=metadata)
    assert set(load_file(path)) == set(tensors)


DAMAGES = {
    "changed weights that still load": nudge_weights,
    "truncated parquet": lambda root: truncate(round_parquet(root)),
    "garbled parquet": lambda root: garble(round_parquet(root)),
    "deleted parquet": lambda root: round_parquet(root).unlink(),
    "truncated weights": lambda root: truncate(ExperimentDir(root).policy_root(1) / "model.safetensors"),
}


def test_verify_passes_an_intact_experiment_and_counts_rounds_and_policies(finished, capsys):
    assert verify_experiment(ExperimentDir(finished)) == (2, 2, [])
    assert main(["verify", f"--experiment_dir={finished}"]) == 0
    assert "verified 2 round(s) and 2 policy folder(s)" in capsys.readouterr().out


def drop_info_records(root: Path) -> None:
    """Rewrites every round's meta/info.json as LeRobot's own writer may: without keys it does not know."""
    for info_path in (root / "rounds").glob("round-*/meta/info.json"):
        info = json.loads(info_path.read_text())
        info.pop("mtdagger", None)  # LeRobot 0.6 rounds hold none
        info_path.write_text(json.dumps(info, indent=4))


def test_the_round_record_survives_lerobot_rewriting_info_json(finished, tmp_path):
    """The record lives in meta/mtdagger.json: verify, resume, merge and report read it there."""
    from lerobot_mtdagger.analysis.results import results_rows
    from lerobot_mtdagger.datasets.experiment_dir import merge_rounds

    copy = damaged_copy(finished, tmp_path, drop_info_records)
    experiment = ExperimentDir(copy)
    assert verify_experiment(experiment) == (2, 2, [])
    assert run(toy_config(copy, "--dagger.rounds=2", "--resume=true"))[-1].startswith("round 2")
    assert verify_experiment(experiment) == (3, 3, [])
    merged = merge_rounds(experiment, [0, 1, 2], tmp_path / "merged")
    assert json.loads((merged / "meta" / "mtdagger.json").read_text())["merged_rounds"] == [0, 1, 2]
    assert {row["round"] for row in results_rows([copy])} == {0, 1, 2}


def remove_record_files(root: Path) -> None:
    """Makes every round look as rounds did before meta/mtdagger.json existed (and so before the ledger).

    Their record was in info.json only, and carried no ledger flag.
    """
    for sidecar in (root / "rounds").glob("round-*/meta/mtdagger.json"):
        record = json.loads(sidecar.read_text())
        record.pop("ledger")
        info = sidecar.parent / "info.json"
        info.write_text(json.dumps({**json.loads(info.read_text()), "mtdagger": record}))
        sidecar.unlink()
    (root / "ledger.json").unlink()
    for training in (root / "policies").glob("round-*/training.json"):
        values = json.loads(training.read_text())
        values.pop("ledger")
        training.write_text(json.dumps(values))


def test_rounds_written_before_the_record_file_existed_still_read_and_verify(finished, tmp_path):
    copy = damaged_copy(finished, tmp_path, remove_record_files)
    assert verify_experiment(ExperimentDir(copy)) == (2, 2, [])
    assert ExperimentDir(copy).read_round_record(1).round == 1


def test_an_info_json_mirror_that_disagrees_with_the_record_file_is_named(finished, tmp_path):
    def edit_mirror(root: Path) -> None:
        round_root = ExperimentDir(root).round_root(1)
        record = json.loads((round_root / "meta" / "mtdagger.json").read_text())
        record["budget"] += 1  # a mirror (LeRobot 0.4 writes one; a copied round may bring one on 0.6)
        info = json.loads((round_root / "meta" / "info.json").read_text())
        (round_root / "meta" / "info.json").write_text(json.dumps({**info, "mtdagger": record}))

    _, _, problems = verify_experiment(ExperimentDir(damaged_copy(finished, tmp_path, edit_mirror)))
    assert any("differs from" in problem and "round-001" in problem for problem in problems), problems


@pytest.mark.parametrize("damage", list(DAMAGES))
def test_verify_names_every_damaged_file_and_exits_non_zero(finished, tmp_path, capsys, damage):
    copy = damaged_copy(finished, tmp_path, DAMAGES[damage])
    _, _, problems = verify_experiment(ExperimentDir(copy))
    damaged = "policies/round-001" if "weights" in damage else "rounds/round-001"
    assert problems and all(damaged in problem for problem in problems), problems
    with pytest.raises(SystemExit) as exit_:
        main(["verify", f"--experiment_dir={copy}"])
    assert exit_.value.code == 1
    out = capsys.readouterr().out
    assert "PROBLEM" in out and ("model.safetensors" in out or ".parquet" in out)


def test_verify_counts_frames_and_episodes_in_the_data_itself(finished, tmp_path):
    def forge_record(root: Path) -> None:  # a record that no longer matches its (intact) data
        edit_round_record(
            ExperimentDir(root).round_root(1), lambda record: record.update(frames=record["frames"] + 1)
        )

    _, _, problems = verify_experiment(ExperimentDir(damaged_copy(finished, tmp_path, forge_record)))
    assert any("data holds" in problem and "frames" in problem for problem in problems), problems


@pytest.mark.parametrize("folder", ["missing", "empty", "not-an-experiment"])
def test_verify_of_a_folder_that_is_not_an_experiment_is_an_error(tmp_path, capsys, folder):
    (tmp_path / "empty").mkdir()
    (tmp_path / "not-an-experiment").mkdir()
    (tmp_path / "not-an-experiment" / "notes.txt").write_text("hello")
    assert main(["verify", f"--experiment_dir={tmp_path / folder}"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "error:" in err[0] and "--output_dir of a `lerobot-mtdagger run`" in err[0]


# -------------------------------------------------------------------------------------------------
# Options validated before anything is written; atomic folders; resume (item 4)
# -------------------------------------------------------------------------------------------------


BAD_RUN_OPTIONS = {
    "--policy.lr=nan": "policy.lr must be finite and > 0",
    "--seed=-1": "seed must be >= 0",
    "--dagger.budget=-3": "budget must be > 0",
    "--policy.device=cuda:99": "policy.device='cuda:99' is not available here",
    "--policy.device=nonsense": "is not a torch device",
}


@pytest.mark.parametrize("option", list(BAD_RUN_OPTIONS))
@pytest.mark.parametrize("mode", ["dagger", "bc"])
def test_a_bad_option_is_refused_before_anything_is_written(tmp_path, capsys, option, mode):
    output = tmp_path / "run"
    status = main(["run", *TOY_RUN, f"--output_dir={output}", f"--mode={mode}", option])
    err = capsys.readouterr().err.strip().splitlines()
    assert status == 2 and len(err) == 1 and BAD_RUN_OPTIONS[option] in err[0]
    assert not output.exists()


def test_a_start_that_fails_before_the_config_is_written_leaves_nothing(tmp_path, monkeypatch):
    output = tmp_path / "run"

    def disk_full(path, payload):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(rounds_module, "write_json_atomic", disk_full)
    with pytest.raises(OSError, match="No space left"):
        run(toy_config(output))
    assert not output.exists() and list(tmp_path.iterdir()) == []


def test_a_start_that_fails_after_creation_leaves_a_resumable_folder(tmp_path, monkeypatch):
    output = tmp_path / "run"

    def diverge(*args, **kwargs):
        raise FloatingPointError("Training loss became nan at step 3; nothing was committed.")

    monkeypatch.setattr(dagger_module, "train_on_rounds", diverge)
    with pytest.raises(FloatingPointError):
        run(toy_config(output, "--dagger.rounds=1"))
    assert (output / "config.json").is_file() and ExperimentDir(output).committed_phases() == []
    monkeypatch.undo()
    assert len(run(toy_config(output, "--dagger.rounds=1", "--resume=true"))) == 2


def test_options_that_do_not_change_results_may_differ_on_resume(finished):
    experiment = ExperimentDir(finished)
    stored = json.loads((finished / "config.json").read_text())
    neutral = copy.deepcopy(stored) | {"progress": True}
    neutral["rollout"] |= {"workers": 0, "worker_backend": "ray", "ray_address": "auto"}
    neutral["policy"]["device"] = "cuda"
    experiment.check_resumable(neutral)
    changed = copy.deepcopy(stored)
    changed["policy"]["lr"] = 1.0
    with pytest.raises(
        UserError, match=r"different config \(policy.lr: 0.0003 -> 1.0\): .*start a new --output_dir"
    ):
        experiment.check_resumable(changed)


def test_a_run_made_before_an_option_existed_resumes_with_its_default(finished, tmp_path):
    older_root = tmp_path / "older"
    shutil.copytree(finished, older_root)
    older = json.loads((older_root / "config.json").read_text())
    for name in [name for name in older["training"] if name.startswith("plateau_")]:  # added later
        del older["training"][name]
    del older["policy"]["pointnet_layer_norm"]
    (older_root / "config.json").write_text(json.dumps(older))
    assert run(toy_config(older_root, "--dagger.rounds=1", "--resume=true")), "resumed: nothing to do"
    with pytest.raises(UserError, match=r"different config \(training.plateau_every: None -> 7\)"):
        run(toy_config(older_root, "--dagger.rounds=1", "--resume=true", "--training.plateau_every=7"))
    with pytest.raises(UserError, match=r"different config \(policy.pointnet_layer_norm: None -> True\)"):
        run(toy_config(older_root, "--dagger.rounds=1", "--resume=true", "--policy.pointnet_layer_norm=true"))


def older_run_without(finished: Path, root: Path, path: str, **changes: str) -> tuple[ExperimentDir, dict]:
    """A copy of ``finished`` whose stored config lacks option ``path`` (a run made before it existed).

    ``changes`` set other stored options first (``group="value"``, e.g. ``suite_name="drawers"``).
    """
    shutil.copytree(finished, root)
    older = json.loads((root / "config.json").read_text())
    for key, value in changes.items():
        group, name = key.split("_", 1)
        older[group][name] = value
    group, name = path.split(".")
    del older[group][name]
    (root / "config.json").write_text(json.dumps(older))
    return ExperimentDir(root), older


def resume_with(experiment: ExperimentDir, older: dict, path: str, value: str) -> None:
    """``check_resumable`` with the stored config plus ``path`` given as ``value``."""
    given = copy.deepcopy(older)
    group, name = path.split(".")
    given[group][name] = value
    experiment.check_resumable(given, added_defaults=RunConfig.option_defaults())


def test_a_drawer_run_made_before_placements_existed_resumes_only_with_the_narrow_one(finished, tmp_path):
    """Those runs used today's ``narrow`` ranges; resuming them with the new default would mix settings."""
    root = tmp_path / "older-drawers"
    experiment, older = older_run_without(finished, root, "suite.placement", suite_name="drawers")
    resume_with(experiment, older, "suite.placement", "narrow")
    with pytest.raises(UserError, match=r"suite.placement: None -> 'kitchen'\) \(drawer runs made before"):
        resume_with(experiment, older, "suite.placement", "kitchen")


def test_a_run_made_before_sampling_existed_resumes_with_uniform_sampling(finished, tmp_path):
    """Before ``training.sampling`` existed every batch was drawn uniformly over frames."""
    experiment, older = older_run_without(finished, tmp_path / "older-sampling", "training.sampling")
    resume_with(experiment, older, "training.sampling", "uniform")
    with pytest.raises(UserError, match=r"training.sampling: None -> 'balanced'"):
        resume_with(experiment, older, "training.sampling", "balanced")


def test_resume_refuses_a_policy_changed_after_commit_that_still_loads(finished, tmp_path):
    copy = damaged_copy(finished, tmp_path, nudge_weights)
    with pytest.raises(CorruptExperimentError, match=r"policies/round-001.*model.safetensors"):
        run(toy_config(copy, "--dagger.rounds=1", "--resume=true"))


def test_resume_refuses_a_round_changed_after_commit_before_running(finished, tmp_path):
    copy = damaged_copy(finished, tmp_path, lambda root: truncate(round_parquet(root)))
    before = sorted(p.relative_to(copy) for p in copy.rglob("*") if p.name != LOCK_FILE)
    with pytest.raises(CorruptExperimentError, match=rf"{round_parquet(copy)} changed after commit"):
        run(toy_config(copy, "--dagger.rounds=1", "--resume=true"))
    assert sorted(p.relative_to(copy) for p in copy.rglob("*") if p.name != LOCK_FILE) == before


def test_merge_is_built_beside_its_target_and_renamed(finished, tmp_path):
    output = tmp_path / "merged"
    (tmp_path / ".merged.merging").mkdir()  # left by a merge that was killed
    (tmp_path / ".merged.merging" / "partial").write_text("x")
    assert main(["merge", f"--experiment_dir={finished}", f"--output={output}"]) == 0
    assert (output / "meta" / "info.json").is_file() and not (tmp_path / ".merged.merging").exists()


def test_merge_of_a_damaged_round_writes_nothing(finished, tmp_path, capsys):
    copy = damaged_copy(finished, tmp_path, lambda root: truncate(round_parquet(root)))
    output = tmp_path / "merged"
    assert main(["merge", f"--experiment_dir={copy}", f"--output={output}"]) == 2
    assert "changed after commit" in capsys.readouterr().err
    assert not output.exists() and not (tmp_path / ".merged.merging").exists()


# -------------------------------------------------------------------------------------------------
# One line per user error, a traceback only with --debug (item 5)
# -------------------------------------------------------------------------------------------------


def bad_inputs(finished: Path, tmp_path: Path) -> dict[str, tuple[list[str], str]]:
    """Command lines a user may get wrong, with what the one error line must say."""
    policy = ExperimentDir(finished).policy_root(1)
    truncated = tmp_path / "truncated-policy"
    shutil.copytree(policy, truncated)
    (truncated / "training.json").unlink()  # no checksums: LeRobot's loader meets the truncated file
    truncate(truncated / "model.safetensors")
    return {
        "eval of a missing path": (["eval", f"--policy_path={tmp_path / 'nowhere'}"], "does not exist"),
        "eval of a dataset": (
            ["eval", f"--policy_path={ExperimentDir(finished).round_root(0)}"],
            "is a LeRobot dataset (no config.json)",
        ),
        "eval of an experiment": (["eval", f"--policy_path={finished}"], f"e.g. {policy}"),
        "eval of truncated weights": (
            ["eval", f"--policy_path={truncated}"],
            f"{truncated / 'model.safetensors'} is not a readable safetensors file",
        ),
        "eval on other observations": (
            ["eval", f"--policy_path={policy}", "--suite.tasks=[reach-v3]", "--workers=0"],
            "The policy takes 'observation.state' of shape",
        ),
        "unclosed list": (
            ["run", "--suite.tasks=[reach-v3,push-v3"],
            "--suite.tasks='[reach-v3,push-v3' is not a valid value",
        ),
        "unknown option": (["run", "--roundz=3"], "unrecognized arguments: --roundz=3"),
        "not an int": (["run", "--dagger.rounds=three"], "Couldn't parse 'three' into an int"),
        "resume of nothing": (
            ["run", f"--output_dir={tmp_path / 'none'}", "--resume=true"],
            "Nothing to resume",
        ),
        "report of nothing": (["report", f"--compare_dir={tmp_path}"], "is not a compare folder"),
        "compare of an unknown method": (
            ["compare", "--methods=[foo]", f"--output_dir={tmp_path / 'cmp'}"],
            "Unknown method(s) ['foo'] in --methods",
        ),
        "compare with a bad run option": (
            ["compare", "--dagger.rounds=-1", f"--output_dir={tmp_path / 'cmp'}"],
            "rounds must be >= 0",
        ),
        "run of an unknown drawer": (
            ["run", "--suite.name=drawers", "--suite.tasks=[drawer-nope]", f"--output_dir={tmp_path / 'r1'}"],
            "Unknown drawer(s) ['drawer-nope']",
        ),
        "run with an unknown observation mode": (
            ["run", "--suite.obs_mode=depth", f"--output_dir={tmp_path / 'r2'}"],
            "Unknown obs_mode 'depth'",
        ),
        "run of the toy suite on point clouds": (
            ["run", "--suite.name=toy", "--suite.obs_mode=pointcloud", f"--output_dir={tmp_path / 'r3'}"],
            "The toy suite has state observations only",
        ),
        "run with a placement outside the drawers": (
            ["run", "--suite.name=toy", "--suite.placement=kitchen", f"--output_dir={tmp_path / 'r4'}"],
            "placement applies to the drawers suite only",
        ),
        "run with no mesh left to render": (
            ["run", "--suite.obs_mode=rgb", "--suite.mesh_detail=0", f"--output_dir={tmp_path / 'r6'}"],
            "mesh_detail must be in (0, 1]",
        ),
        "eval with too much mesh detail": (
            [
                "eval",
                f"--policy_path={finished / 'policies' / 'round-001'}",
                "--suite.name=toy",
                "--suite.mesh_detail=2",
            ],
            "mesh_detail must be in (0, 1]",
        ),
        "run with an unknown placement": (
            ["run", "--suite.name=drawers", "--suite.placement=office", f"--output_dir={tmp_path / 'r5'}"],
            "Unknown drawer placement 'office'",
        ),
        "merge of a non-experiment": (
            ["merge", f"--experiment_dir={tmp_path}", f"--output={tmp_path / 'm'}"],
            "is not a lerobot-mtdagger experiment",
        ),
    }


def test_every_bad_input_is_one_error_line_and_exit_2(finished, tmp_path, capsys):
    for name, (argv, expected) in bad_inputs(finished, tmp_path).items():
        assert main(argv) == 2, name
        captured = capsys.readouterr()
        err = captured.err.strip().splitlines()
        assert len(err) == 1, (name, err)
        assert err[0].startswith(f"lerobot-mtdagger {argv[0]}: error: ") and expected in err[0], (name, err)
        assert "Traceback" not in captured.out + captured.err
    assert not (tmp_path / "cmp").exists(), "compare wrote before checking its options"
    assert not any((tmp_path / f"r{i}").exists() for i in range(1, 6)), "run wrote before checking its suite"


def test_debug_shows_the_traceback_of_a_user_error(tmp_path):
    with pytest.raises(UserError, match="does not exist"):
        main(["eval", f"--policy_path={tmp_path / 'nowhere'}", "--debug"])


def test_eval_of_a_hub_id_that_cannot_be_fetched_is_one_error_line(monkeypatch, capsys):
    import huggingface_hub.constants

    monkeypatch.setattr(huggingface_hub.constants, "HF_HUB_OFFLINE", True)  # no network in the test
    assert main(["eval", "--policy_path=nobody/no-such-policy"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--policy_path=nobody/no-such-policy is not a local path" in err[0], err
    assert "not in the cache while HF_HUB_OFFLINE is set" in err[0], err


def test_eval_of_an_rgb_policy_runs_and_a_wrong_image_size_is_named(tmp_path, capsys):
    """An image policy takes channel-first inputs where the suite's features are channel-last."""
    experiment = tmp_path / "rgb"
    rgb_run = [
        "run",
        "--suite.name=metaworld-mt10",
        "--suite.tasks=[reach-v3]",
        "--suite.obs_mode=rgb",
        "--suite.image_size=32",
        "--suite.episode_length=30",
        "--dagger.rounds=0",
        "--dagger.initial_demos=1",
        "--training.steps_per_round=2",
        "--rollout.eval_episodes=1",
        "--rollout.workers=0",
        "--progress=false",
        f"--output_dir={experiment}",
    ]
    assert main(rgb_run) == 0
    policy = ExperimentDir(experiment).policy_root(0)
    output = tmp_path / "eval.json"
    evaluation = ["eval", f"--policy_path={policy}", "--episodes=1", "--seed=3", "--workers=0"]
    assert main([*evaluation, f"--output={output}"]) == 0, capsys.readouterr().err
    result = json.loads(output.read_text())
    assert result["task_names"] == ["reach-v3"], "the suite's tasks default to the policy's"
    assert result["episodes"] == [1]

    capsys.readouterr()
    assert main([*evaluation, "--suite.image_size=48"]) == 2
    err = capsys.readouterr().err
    assert "'observation.image' of shape (3, 32, 32), the suite gives (3, 48, 48)" in err, err

    assert main([*evaluation, "--suite.tasks=[push-v3]"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "trained on ['reach-v3'], not on ['push-v3']" in err[0], err


def test_a_run_of_a_rescaled_preset_resumes_with_its_paper_preset(finished, tmp_path):
    """``drawers-pointcloud`` and ``metaworld-pixels`` were scaled to a CPU; their former values live on."""
    older_root = tmp_path / "older-preset"
    shutil.copytree(finished, older_root)
    paper = RunConfig(preset="drawers-pointcloud-paper", output_dir=older_root).to_dict()
    (older_root / "config.json").write_text(json.dumps(paper | {"preset": "drawers-pointcloud"}))
    experiment = ExperimentDir(older_root)
    experiment.check_resumable(RunConfig(preset="drawers-pointcloud-paper", output_dir=older_root).to_dict())
    rescaled = RunConfig(preset="drawers-pointcloud", output_dir=older_root).to_dict()
    expected = r"dagger.initial_demos: 30 -> 10.*resume it with that preset\)"
    with pytest.raises(UserError, match=expected) as info:
        experiment.check_resumable(rescaled)
    assert "--preset=drawers-pointcloud-paper" in str(info.value)


def test_a_drawer_run_made_before_placement_settings_is_told_to_add_narrow(finished, tmp_path):
    """A stored config without ``suite.placement`` resumes with ``narrow`` (what it drew), and a resume
    with today's default names that option, also for a rescaled preset's run."""
    older_root = tmp_path / "older-drawers"
    shutil.copytree(finished, older_root)
    for preset in ("drawers-pointcloud-paper", "drawers-pointcloud"):
        narrow = RunConfig(preset=preset, output_dir=older_root).to_dict()
        narrow["suite"]["placement"] = "narrow"
        stored = json.loads(json.dumps(narrow))
        del stored["suite"]["placement"]
        (older_root / "config.json").write_text(json.dumps(stored))
        experiment = ExperimentDir(older_root)
        experiment.check_resumable(narrow, added_defaults=RunConfig.option_defaults())
        today = RunConfig(preset=preset, output_dir=older_root).to_dict()
        with pytest.raises(UserError) as info:
            experiment.check_resumable(today, added_defaults=RunConfig.option_defaults())
        message = str(info.value)
        assert "suite.placement: None -> 'kitchen'" in message, message
        assert "used --suite.placement=narrow)" in message and "-paper" not in message, message


def test_a_pixel_run_made_before_balanced_sampling_is_told_to_add_uniform(finished, tmp_path):
    """``metaworld-pixels`` samples balanced (DAgger since 2026-11-26, BC since 2026-11-27); older runs
    resume uniform."""
    older_root = tmp_path / "older-pixels"
    shutil.copytree(finished, older_root)
    uniform = TrainingConfig(sampling="uniform")
    before = RunConfig(preset="metaworld-pixels", training=uniform, output_dir=older_root).to_dict()
    (older_root / "config.json").write_text(json.dumps(before))
    experiment = ExperimentDir(older_root)
    experiment.check_resumable(before)
    today = RunConfig(preset="metaworld-pixels", output_dir=older_root).to_dict()
    with pytest.raises(UserError) as info:
        experiment.check_resumable(today)
    message = str(info.value)
    assert "training.sampling: 'uniform' -> 'balanced'" in message, message
    assert "used --training.sampling=uniform: add it" in message and "-paper" not in message, message
    uniform = TrainingConfig(sampling="uniform")  # a new one: a RunConfig fills the one it is given
    bc_before = RunConfig(preset="metaworld-pixels", mode="bc", training=uniform, output_dir=older_root)
    (older_root / "config.json").write_text(json.dumps(bc_before.to_dict()))
    experiment.check_resumable(bc_before.to_dict())
    bc_today = RunConfig(preset="metaworld-pixels", mode="bc", output_dir=older_root).to_dict()
    with pytest.raises(UserError, match=r"before 2026-11-27 .* used --training.sampling=uniform: add it"):
        experiment.check_resumable(bc_today)
    paper_values = RunConfig(preset="metaworld-pixels-paper", output_dir=older_root).to_dict()
    (older_root / "config.json").write_text(json.dumps(paper_values | {"preset": "metaworld-pixels"}))
    with pytest.raises(UserError, match=r"resume it with that preset\)"):
        experiment.check_resumable(today)


def test_a_pixel_run_made_before_ten_passes_is_told_to_add_fixed_steps(finished, tmp_path):
    """``metaworld-pixels``' DAgger phases make 10 passes since 2026-11-29; its BC keeps fixed steps."""
    older_root = tmp_path / "older-pixels"
    shutil.copytree(finished, older_root)
    fixed = {"steps_rule": "fixed", "epochs": 100.0}
    before = RunConfig(preset="metaworld-pixels", training=TrainingConfig(**fixed), output_dir=older_root)
    (older_root / "config.json").write_text(json.dumps(before.to_dict()))
    experiment = ExperimentDir(older_root)
    experiment.check_resumable(before.to_dict())
    today = RunConfig(preset="metaworld-pixels", output_dir=older_root).to_dict()
    assert today["training"]["steps_rule"] == "epochs" and today["training"]["epochs"] == 10.0
    with pytest.raises(UserError) as info:
        experiment.check_resumable(today)
    message = str(info.value)
    assert "training.steps_rule: 'fixed' -> 'epochs'" in message, message
    named = "used --training.epochs=100.0 --training.steps_rule=fixed: add it"
    assert f"before 2026-11-29 with --preset=metaworld-pixels {named}" in message, message
    bc = RunConfig(preset="metaworld-pixels", mode="bc", output_dir=older_root)
    assert (bc.training.steps_rule, bc.training.epochs) == ("fixed", 100.0)
    (older_root / "config.json").write_text(json.dumps(bc.to_dict()))
    experiment.check_resumable(bc.to_dict())  # BC's training did not change
    oldest = TrainingConfig(sampling="uniform", **fixed)
    (older_root / "config.json").write_text(
        json.dumps(RunConfig(preset="metaworld-pixels", training=oldest, output_dir=older_root).to_dict())
    )
    with pytest.raises(UserError) as info:
        experiment.check_resumable(today)
    message = str(info.value)
    assert "before 2026-11-27 with --preset=metaworld-pixels used --" in message, message
    for option in ("--training.sampling=uniform", "--training.steps_rule=fixed", "--training.epochs=100.0"):
        assert option in message, message


def test_the_pixels_preset_trains_dagger_ten_passes_and_bc_its_fixed_steps():
    dagger = RunConfig(preset="metaworld-pixels")
    assert dagger.phase_steps(6400) == 1000 and dagger.phase_steps(6401) == 1001  # 10 passes, batch 64
    bc = RunConfig(preset="metaworld-pixels", mode="bc")
    assert bc.phase_steps(6400) == bc.phase_steps(55_000) == 1500 * (5 + 1)
    stated = RunConfig(preset="metaworld-pixels", training=TrainingConfig(steps_rule="fixed"))
    assert stated.phase_steps(55_000) == 1500
