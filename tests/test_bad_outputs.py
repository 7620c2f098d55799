"""Output paths, devices, sizes and config files refused in one line, exit 2, before anything is written."""

from __future__ import annotations

import importlib.util
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from lerobot_mtdagger.cli import main

TOY = ["--suite.name=toy", "--dagger.rounds=0", "--dagger.initial_demos=1", "--rollout.eval_episodes=1"]
TOY += ["--training.steps_per_round=2", "--rollout.workers=0", "--progress=false"]


@pytest.fixture
def read_only(tmp_path):
    folder = tmp_path / "read-only"
    folder.mkdir()
    folder.chmod(0o555)
    yield folder
    folder.chmod(0o755)


def _refused(capsys, args: list[str], message: str) -> None:
    assert main(args) == 2
    error = capsys.readouterr().err
    assert message in error, error
    assert len(error.strip().splitlines()) == 1, error


def test_run_refuses_an_output_dir_that_is_a_file_or_under_one(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    _refused(capsys, ["run", *TOY, f"--output_dir={afile}"], "is a file: give a folder path")
    _refused(capsys, ["run", *TOY, f"--output_dir={afile / 'x'}"], f"lies under the file {afile}")
    assert afile.read_text() == "x"


@pytest.mark.skipif(os.geteuid() == 0, reason="root writes into a read-only folder")
def test_run_refuses_an_output_dir_in_a_read_only_folder(read_only, capsys):
    _refused(capsys, ["run", *TOY, f"--output_dir={read_only / 'x'}"], "cannot be written")


def test_run_refuses_an_output_dir_on_a_file_system_nobody_writes(capsys):
    # /proc refuses new files even to root: the probe creates one, not just asks os.access
    _refused(capsys, ["run", *TOY, "--output_dir=/proc/mtdagger-test/x"], "/proc is not writable here")


def test_merge_report_and_eval_refuse_bad_outputs_before_working(tmp_path, capsys):
    afile = tmp_path / "afile"
    afile.write_text("x")
    experiment = tmp_path / "exp"
    assert main(["run", *TOY, f"--output_dir={experiment}"]) == 0
    capsys.readouterr()
    _refused(capsys, ["merge", f"--experiment_dir={experiment}", f"--output={afile}"], "is a file")
    _refused(capsys, ["report", f"--experiments=[{experiment}]", f"--output_dir={afile}"], "is a file")
    policy = experiment / "policies" / "round-000"
    eval_args = ["eval", f"--policy_path={policy}", "--suite.name=toy", "--episodes=1"]
    _refused(capsys, [*eval_args, f"--output={afile / 'r.json'}"], "lies under the file")
    _refused(capsys, [*eval_args, f"--output={tmp_path}"], "is a folder: give a file path")
    assert afile.read_text() == "x"


@pytest.mark.parametrize(
    ("option", "message"),
    [
        ("--policy.device=cpu:9", "names a CPU that does not exist"),
        ("--suite.image_size=100000", "suite.image_size must be <= 480"),
        ("--suite.num_points=1000000000", "suite.num_points must be <= 65536"),
        ("--config_path=nonexistent.yaml", "--config_path=nonexistent.yaml is not a file"),
    ],
)
def test_impossible_options_are_refused_before_anything_is_written(tmp_path, capsys, option, message):
    out = tmp_path / "out"
    _refused(capsys, ["run", *TOY, option, f"--output_dir={out}"], message)
    assert not out.exists()


@pytest.mark.parametrize("seeds", ["[-1]", "[0,0]", "[]"])
def test_compare_refuses_bad_seeds_before_any_run(tmp_path, capsys, seeds):
    out = tmp_path / "cmp"
    _refused(
        capsys, ["compare", "--methods=[need]", f"--seeds={seeds}", f"--output_dir={out}", *TOY], "--seeds"
    )
    assert not out.exists()


def test_compare_experiments_ignores_what_never_changes_a_result(tmp_path):
    """A resumed run, or one with other worker counts, is the same experiment; --strict says otherwise."""
    script = Path(__file__).resolve().parents[1] / "scripts" / "compare_experiments.py"
    first = tmp_path / "first"
    assert main(["run", *TOY, f"--output_dir={first}"]) == 0
    second = tmp_path / "second"
    shutil.copytree(first, second)
    path = second / "rounds" / "round-000" / "meta" / "mtdagger.json"
    record = json.loads(path.read_text())
    record["config"]["resume"] = True
    record["config"]["rollout"]["workers"] = 7
    path.write_text(json.dumps(record))

    def compare(*flags: str) -> subprocess.CompletedProcess:
        return subprocess.run(
            [sys.executable, str(script), str(first), str(second), *flags], capture_output=True, text=True
        )

    assert compare().returncode == 0
    strict = compare("--strict")
    assert strict.returncode == 1 and "config.resume" in strict.stdout and "rollout.workers" in strict.stdout
    record["config"]["dagger"]["beta"] = 0.7
    path.write_text(json.dumps(record))
    assert "config.dagger.beta" in compare().stdout


def test_compare_experiments_starts_without_torch_or_lerobot():
    """Comparing two folders' records needs neither (importing them takes several seconds a call)."""
    script = Path(__file__).resolve().parents[1] / "scripts" / "compare_experiments.py"
    load = (
        "import importlib.util, sys; "
        f"spec = importlib.util.spec_from_file_location('compare_experiments', {str(script)!r}); "
        "spec.loader.exec_module(importlib.util.module_from_spec(spec)); "
        "print(sorted({m.split('.')[0] for m in sys.modules} & {'torch', 'lerobot'}))"
    )
    loaded = subprocess.run([sys.executable, "-c", load], capture_output=True, text=True, check=True)
    assert loaded.stdout.strip() == "[]"


def test_a_refused_run_prints_no_experiment_header(tmp_path, capsys):
    out = tmp_path / "out"
    assert main(["run", *TOY, f"--output_dir={out}"]) == 0
    assert capsys.readouterr().out.startswith(f"experiment {out} (need, seed 0):")
    assert main(["run", *TOY, f"--output_dir={out}"]) == 2  # exists: refused
    captured = capsys.readouterr()
    assert captured.out == "" and "already exists" in captured.err


@pytest.mark.skipif(importlib.util.find_spec("grpc") is not None, reason="ray[client] is installed here")
def test_a_ray_client_address_without_ray_client_is_refused_before_anything_is_written(tmp_path, capsys):
    pytest.importorskip("ray")
    out = tmp_path / "out"
    ray = ["--rollout.worker_backend=ray", "--rollout.ray_address=ray://127.0.0.1:1"]
    _refused(capsys, ["run", *TOY, *ray, f"--output_dir={out}"], 'needs pip install "ray[client]"')
    assert not out.exists()


def test_eval_of_a_policy_from_another_suite_names_the_suite_option(tmp_path, capsys):
    experiment = tmp_path / "toy"
    assert main(["run", *TOY, f"--output_dir={experiment}"]) == 0
    capsys.readouterr()
    policy = experiment / "policies" / "round-000"
    args = ["eval", f"--policy_path={policy}", "--episodes=1", "--workers=0"]  # MT10 by default
    _refused(capsys, args, "none of which --suite.name=metaworld-mt10 has")
