"""Smoke tests of the ``lerobot-mtdagger`` command and the synthetic-task simulation."""

from __future__ import annotations

import ast
import fnmatch
import json
import os
import shutil
import socket
import subprocess
import sys
import time
import zipfile
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pytest

from lerobot_mtdagger.analysis.simulate import SyntheticTasks, simulate
from lerobot_mtdagger.cli import COMMANDS, main
from lerobot_mtdagger.datasets_cards import card_template
from lerobot_mtdagger.scheduler import allocation_mismatches, make_scheduler


def test_console_script_demo_runs_and_writes_records(tmp_path):
    output = tmp_path / "rounds.json"
    result = subprocess.run(
        [
            sys.executable,
            "-m",
            "lerobot_mtdagger.cli",
            "demo",
            "--scheduler.type=gain",
            "--rounds=3",
            f"--output={output}",
        ],
        capture_output=True,
        text=True,
        check=True,
    )
    assert "round 3: allocation" in result.stdout
    records = json.loads(output.read_text())
    assert [r["round"] for r in records] == [1, 2, 3]
    for record in records:
        assert sum(record["allocation"]["episodes_per_task"]) == 30
        assert allocation_mismatches(record["allocation"]) == []


def test_help_and_unknown_command(capsys):
    assert main([]) == 0
    assert "demo" in capsys.readouterr().out
    assert main(["train-everything"]) == 2
    assert "unknown command 'train-everything'" in capsys.readouterr().err


def test_demo_rejects_bad_options_with_the_fields_message(capsys):
    assert main(["demo", "--num_tasks=0"]) == 2
    assert "num_tasks must be >= 1, got 0" in capsys.readouterr().err
    assert main(["demo", "--scheduler.temperature=0"]) == 2
    assert "scheduler.temperature must be a finite number > 0" in capsys.readouterr().err


@pytest.mark.parametrize("method", ["need", "gain"])
def test_performance_aware_methods_favour_hard_synthetic_tasks(method):
    hard_share = {}
    for name in (method, "uniform"):
        tasks = SyntheticTasks.spread(8, easiest=1.0, hardest=40.0)
        simulate(make_scheduler(name, 8), tasks, rounds=5, budget=24, initial_demos=3, seed=0)
        hard_share[name] = tasks.demos[-3:].sum() / tasks.demos.sum()
    assert hard_share[method] > hard_share["uniform"]


def test_simulation_is_reproducible_under_a_seed():
    def run():
        tasks = SyntheticTasks.spread(5)
        history = simulate(make_scheduler("need", 5), tasks, rounds=4, budget=15, initial_demos=2, seed=7)
        return [r.allocation.episodes_per_task for r in history]

    assert run() == run()
    assert np.all(np.asarray(run()).sum(axis=1) == 15)


def test_dataset_card_template_ships_with_the_package(tmp_path):
    assert "{{ allocation_table }}" in card_template()  # the importable package (here: the source tree)

    # The built distribution: a wheel of a copy of the project (building in place would write build/ into
    # the checkout and could package stale files from it). The copy skips what .gitignore ignores.
    repo = Path(__file__).resolve().parents[1]
    ignored = [line.rstrip("/") for line in (repo / ".gitignore").read_text().split() if line.strip()]
    source = tmp_path / "source"
    shutil.copytree(repo, source, ignore=shutil.ignore_patterns(".git", *ignored))
    pip_wheel = [sys.executable, "-m", "pip", "wheel", str(source), "--no-deps", "--no-build-isolation"]
    subprocess.run([*pip_wheel, "-w", str(tmp_path / "dist")], check=True, capture_output=True, text=True)
    (wheel,) = (tmp_path / "dist").glob("lerobot_mtdagger-*.whl")
    with zipfile.ZipFile(wheel) as archive:
        cards = fnmatch.filter(archive.namelist(), "lerobot_mtdagger/datasets_cards/*.md")
        assert "lerobot_mtdagger/datasets_cards/mtdagger_card.md" in cards, f"cards in the wheel: {cards}"
        card = archive.read("lerobot_mtdagger/datasets_cards/mtdagger_card.md").decode("utf-8")
    assert "{{ allocation_table }}" in card


@pytest.mark.parametrize(
    ("inputs", "given", "expected"),
    [
        ({"observation.state": (4,), "observation.pointcloud": (512, 3)}, {}, ("pointcloud", 512, 84)),
        ({"observation.state": (7,), "observation.image": (3, 64, 64)}, {}, ("rgb", 1024, 64)),
        ({"observation.state": (39,)}, {}, ("state", 1024, 84)),
        ({"observation.pointcloud": (512, 3)}, {"num_points": 256}, ("pointcloud", 256, 84)),
    ],
)
def test_eval_takes_the_observation_options_the_policy_was_trained_with(inputs, given, expected):
    """A point-cloud policy evaluates without --suite.obs_mode / --suite.num_points; what is given wins."""
    from types import SimpleNamespace

    from lerobot.configs.types import FeatureType, PolicyFeature

    from lerobot_mtdagger.commands.configs.eval import EvalConfig
    from lerobot_mtdagger.commands.eval import observation_options
    from lerobot_mtdagger.envs import SuiteConfig

    features = {
        key: PolicyFeature(FeatureType.VISUAL if "image" in key else FeatureType.STATE, shape)
        for key, shape in inputs.items()
    }
    runner = SimpleNamespace(policy=SimpleNamespace(config=SimpleNamespace(input_features=features)))
    options = observation_options(runner, EvalConfig(policy_path="p", suite=SuiteConfig(**given)).suite)
    assert (options["obs_mode"], options["num_points"], options["image_size"]) == expected


COMMAND_OPTIONS = {
    "run": [
        "--preset",
        "--suite.name",
        "--dagger.rounds",
        "--scheduler.R0",
        "--policy.type",
        "--expert.noise",
    ],
    "compare": ["--methods", "--seeds", "--bc_budgets", "--jobs", "--cores", "--launcher", "--share_round0"],
    "eval": ["--policy_path", "--suite.name", "--episodes", "--output"],
    "shift": ["--policy_path", "--episodes"],
    "verify": ["--experiment_dir"],
    "merge": ["--experiment_dir", "--output", "--up_to_round"],
    "push": ["--experiment_dir", "--repo_id", "--policy_repo_id"],
    "report": ["--experiments", "--compare_dir", "--results", "--records"],
    "plan": ["--datasets", "--budget", "--budget_minutes", "--previous", "--verify", "--scheduler.type"],
    "demo": ["--num_tasks", "--rounds", "--scheduler.temperature"],
}


@pytest.mark.parametrize("command", sorted(COMMAND_OPTIONS))
def test_each_commands_help_lists_its_own_options_one_line_each(capsys, command):
    with pytest.raises(SystemExit) as exited:
        main([command, "--help"])
    assert exited.value.code == 0
    page = capsys.readouterr().out
    assert page.startswith(f"usage: lerobot-mtdagger {command} ")
    lines = {line.split()[0].split("=")[0]: line for line in page.splitlines() if line.startswith("  --")}
    for option in COMMAND_OPTIONS[command]:
        assert option in lines, (option, sorted(lines))
        help_text = lines[option].split(None, 1)[1] if len(lines[option].split(None, 1)) > 1 else ""
        assert help_text and not help_text.startswith("(default"), lines[option]  # a line of help, not bare
    assert "Attributes:" not in page and "def " not in page and "lambda" not in page  # no source text
    if command == "compare":  # its own options, and where the run options are listed
        assert "--dagger.rounds" not in page and "lerobot-mtdagger run --help" in page


def test_run_help_names_lerobot_students_and_describes_one_when_asked(capsys):
    with pytest.raises(SystemExit):
        main(["run", "--help"])
    page = capsys.readouterr().out
    assert "--policy.type={mtdagger,act,diffusion}" in page and "--policy.chunk_size" not in page
    with pytest.raises(SystemExit):
        main(["run", "--policy.type=act", "--help"])
    assert "--policy.chunk_size=INT" in capsys.readouterr().out


IN_A_FRESH_PROCESS = """
import sys
from lerobot_mtdagger.cli import main
try:
    status = main(sys.argv[1:])
except SystemExit as exit_:
    status = exit_.code
print(status, [m for m in ('torch', 'lerobot') if m in sys.modules])
"""
"""The command line run in a new interpreter, which then prints its status and the heavy libraries loaded."""


@dataclass
class FreshRun:
    """What ``run_fresh`` saw: the exit status, the heavy libraries loaded, the error lines, the time."""

    status: int
    heavy: list[str]
    errors: list[str]
    seconds: float


def run_fresh(args: list[str], env: dict[str, str] | None = None) -> FreshRun:
    """``lerobot-mtdagger ARGS`` in a new interpreter (``IN_A_FRESH_PROCESS``)."""
    start = time.perf_counter()
    result = subprocess.run(
        [sys.executable, "-c", IN_A_FRESH_PROCESS, *args],
        capture_output=True,
        text=True,
        timeout=120,
        env={**os.environ, **(env or {})},
    )
    seconds = time.perf_counter() - start
    assert result.returncode == 0, result.stderr[-3000:]
    status, heavy = result.stdout.strip().splitlines()[-1].split(" ", 1)
    return FreshRun(int(status), ast.literal_eval(heavy), result.stderr.strip().splitlines(), seconds)


REFUSED_OPTION = {"compare": "--seeds=[-1]"}
"""An option each command refuses as it parses (``--nope=1``, an unknown option, unless named here:
compare passes unknown options on to its runs)."""


@pytest.mark.parametrize(
    "args",
    [[command, "--help"] for command in COMMANDS]
    + [[command, REFUSED_OPTION.get(command, "--nope=1")] for command in COMMANDS]
    + [["run", "--preset=nope"], ["--help"]],
    ids=lambda args: " ".join(args),
)
def test_help_and_a_refused_option_import_neither_torch_nor_lerobot(args):
    """What makes them answer in under a second instead of 9-18 s (``benchmarks/bench_cli_startup.sh``)."""
    run = run_fresh(args)
    assert run.heavy == [], (run.heavy, run.errors[-5:])
    assert run.status == (0 if "--help" in args else 2), run.errors[-5:]


def missing_path_refusals(tmp_path: Path) -> dict[str, tuple[list[str], Path, str]]:
    """Command lines naming a path that is not there (or, for merge, one that is): the path, the fix."""
    missing, experiment, taken = tmp_path / "no-such-folder", tmp_path / "experiment", tmp_path / "taken"
    return {
        "verify": (["verify", f"--experiment_dir={missing}"], missing, "pass the --output_dir of a"),
        "merge into an existing folder": (
            ["merge", f"--experiment_dir={experiment}", f"--output={taken}"],
            taken,
            "choose another --output",
        ),
        "merge": (["merge", f"--experiment_dir={missing}", f"--output={taken}/merged"], missing, "pass the"),
        "report": (["report", f"--experiments=[{missing}]"], missing, "give experiment folders"),
        "report --results": (["report", f"--results=[{missing}]"], missing, "pass the results.json"),
        "replay": (["replay", f"--records=[{missing}]"], missing, "give the folder"),
        "eval": (["eval", f"--policy_path={missing}"], missing, "--policy_path takes a policy folder"),
        "shift": (["shift", f"--policy_path={missing}"], missing, "--policy_path takes a policy folder"),
        "push": (["push", f"--experiment_dir={missing}", "--repo_id=me/rounds"], missing, "pass the"),
        "plan": (
            ["plan", f"--datasets=[{missing}]", "--budget=5", f"--output={tmp_path}/p.json"],
            missing,
            "give",
        ),
        "plan --previous": (
            [
                "plan",
                f"--datasets=[{missing}]",
                "--budget=5",
                f"--previous={missing}",
                f"--output={tmp_path}/p.json",
            ],
            missing,
            "give the plan file",
        ),
        "plan --verify": (["plan", f"--verify={missing}"], missing, "give the plan file"),
    }


@pytest.mark.parametrize("case", sorted(missing_path_refusals(Path("/unused"))), ids=str)
def test_a_missing_path_is_refused_in_one_line_before_torch_or_lerobot_load(tmp_path, case):
    args, path, fix = missing_path_refusals(tmp_path)[case]
    (tmp_path / "experiment").mkdir()  # as far as the check looks: a folder with a config.json
    (tmp_path / "experiment" / "config.json").write_text("{}")
    (tmp_path / "taken").mkdir()
    run = run_fresh(args)
    assert run.status == 2 and len(run.errors) == 1, run.errors[-5:]
    assert run.errors[0].startswith(f"lerobot-mtdagger {args[0]}: error: "), run.errors
    assert str(path) in run.errors[0] and fix in run.errors[0], run.errors
    assert run.heavy == [], run.heavy


def closed_port() -> int:
    """A local port nothing listens on (a connection to it is refused at once)."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return probe.getsockname()[1]


HUB_REFUSALS = {
    "eval": (["eval", "--policy_path=nobody/not-a-policy"], "nobody/not-a-policy", "model repo"),
    "shift": (["shift", "--policy_path=bad/nonexistent"], "bad/nonexistent", "model repo"),
    "plan": (["plan", "--datasets=[data/sesion1]", "--budget=5"], "data/sesion1", "dataset repo"),
}
"""Repo ids (or local paths mistyped into the shape of one) that no Hub answers for: the id, the repo type."""


@pytest.mark.parametrize("command", sorted(HUB_REFUSALS))
@pytest.mark.parametrize("hub", ["unreachable", "offline"])
def test_a_repo_id_the_hub_cannot_confirm_is_one_line_in_seconds(tmp_path, command, hub):
    """No network needed: the Hub's address is a closed local port, or ``HF_HUB_OFFLINE`` is set."""
    args, repo_id, repo_type = HUB_REFUSALS[command]
    args = args + ([f"--output={tmp_path / 'plan.json'}"] if command == "plan" else [])
    env = {"HF_HOME": str(tmp_path / "hf-home"), "HF_LEROBOT_HOME": str(tmp_path / "lerobot-home")}
    if hub == "offline":
        env["HF_HUB_OFFLINE"] = "1"
    else:
        env |= {"HF_HUB_OFFLINE": "0", "HF_ENDPOINT": f"http://127.0.0.1:{closed_port()}"}
    run = run_fresh(args, env)
    assert run.status == 2 and len(run.errors) == 1, run.errors[-5:]
    assert repo_id in run.errors[0] and repo_type in run.errors[0], run.errors
    expected = "HF_HUB_OFFLINE is set" if hub == "offline" else "the Hub cannot be asked"
    assert expected in run.errors[0] and run.heavy == [], (run.errors, run.heavy)
    assert run.seconds < 5, run.seconds
