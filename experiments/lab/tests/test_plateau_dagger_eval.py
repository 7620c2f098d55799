"""``plateau-dagger-eval``: its decision file, its runs and its table, on stand-in folders (nothing runs)."""

from __future__ import annotations

import csv
import importlib.util
import io
import json
import os
import shutil
import subprocess
import tarfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[3]
STUDY = ROOT / "experiments" / "plateau-dagger-eval"
COLUMNS = ["experiment", "method", "bc", "seed", "round", "demos_per_task_mean", "eval_success_mean"]
SEEDS = (0, 1, 2, 3, 4)
DECIDED = (
    "plain check: today's code gives the reused curve in every round (seed 100)\n\n## need\n\n"
    "Decision: the best training of need is {need}.\n\n## uniform\n\n"
    "Decision: the best training of uniform is {uniform} (none qualified: the highest mean; BC's training "
    "needs more study).\n"
)


@pytest.fixture(scope="module")
def table():
    spec = importlib.util.spec_from_file_location("plateau_dagger_eval_table", STUDY / "table.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_results(path: Path, rows: list[tuple[str, bool, int, int, float]]) -> None:
    """``(method, bc, seed, round, success)`` rows as compare writes them (3 + 3 x round demos per task)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        for method, bc, seed, round_, success in rows:
            writer.writerow(
                [f"runs/{method}-seed{seed}", method, str(bc), seed, round_, 3.0 + 3 * round_, success]
            )


def need_success(seed: int, round_: int) -> float:
    """Stand-in need: 0.85 at 33 demos; over 45-63 demos 0.90 + 0.01 x seed, 0.007 more at 63."""
    if round_ < 14:
        return 0.85 if round_ == 10 else 0.80
    return 0.90 + 0.01 * seed + (0.007 if round_ == 20 else 0.0)


def uniform_success(seed: int, round_: int) -> float:
    """Stand-in uniform: 0.88 at 33 demos; over 45-63 demos 0.92 + 0.002 x seed."""
    if round_ < 14:
        return 0.88 if round_ == 10 else 0.80
    return 0.92 + 0.002 * seed


def bc_success(seed: int, budget: int) -> float:
    """Stand-in best BC: 0.90 at 33 demos, 0.93 + 0.01 x seed at 45, 0.95 at 63."""
    return {33: 0.90, 45: 0.93 + 0.01 * seed, 63: 0.95}[budget]


def dagger_rows(method: str, seed: int, success, last_round: int = 20) -> list:
    return [(method, False, seed, r, success(seed, r)) for r in range(last_round + 1)]


def write_bc_records(folder: Path) -> Path:
    """The best BC's saved records as ``../beyond-plateau-best-bc/records`` holds them (as folders)."""
    for seed in SEEDS:
        for budget in (33, 45, 63):
            phase = folder / "cosine" / f"bc-{budget}demos-seed{seed}" / "policies" / "round-000"
            phase.mkdir(parents=True)
            (phase / "training.json").write_text(json.dumps({"eval": {"mean": bc_success(seed, budget)}}))
    return folder


@pytest.fixture
def stand_in(table, tmp_path, monkeypatch):
    """need chose cosine (this study's runs), uniform plain (the reused runs); the stand-in best BC."""
    out = tmp_path / "eval"
    out.mkdir()
    (out / "decision.txt").write_text(DECIDED.format(need="cosine", uniform="plain"))
    for seed in SEEDS:
        bc_decoy = [("bc", True, seed, 0, 0.1)]  # a BC row in the table is never a DAgger phase
        write_results(
            out / f"cosine-seed{seed}" / "results.csv", dagger_rows("need", seed, need_success) + bc_decoy
        )
    plain = []
    for seed in SEEDS:  # plain need is there too: need chose cosine, so its plain runs must not be read
        plain += dagger_rows("uniform", seed, uniform_success) + dagger_rows("need", seed, lambda s, r: 0.5)
    write_results(tmp_path / "plain" / "results.csv", plain)
    monkeypatch.setattr(table, "PLAIN_RESULTS", tmp_path / "plain" / "results.csv")
    monkeypatch.setattr(table, "BEST_BC_RECORDS", write_bc_records(tmp_path / "bc"))
    return out


def printed(table, capsys, *argv: str) -> str:
    assert table.main(list(argv)) == 0
    return capsys.readouterr().out


# The stand-in's paired numbers by hand, per seed s over 45-63 demos per task (need: its 7 phases,
# BC: 45 and 63): need 0.901 + 0.01 s, uniform 0.92 + 0.002 s, BC 0.94 + 0.005 s.
# need - BC = -0.039 + 0.005 s, mean -0.029, sd 0.005 sqrt(2.5), 95% t (4 df, 2.7764) half-width
# 2.7764 x 0.005 sqrt(2.5) / sqrt(5) = 0.0098: [-0.0388, -0.0192].
PRIMARY = (
    "primary (fixed in run.sh before any run): need(cosine) - best BC, mean over 45-63 demos per task: "
    "-0.039 / -0.034 / -0.029 / -0.024 / -0.019; -0.029 [-0.039, -0.019] *"
)
# uniform - BC = -0.020 - 0.003 s: mean -0.026, half-width 2.7764 x 0.003 sqrt(0.5) = 0.0059.
UNIFORM_BC = (
    "secondary: uniform(plain) - best BC, mean over 45-63 demos per task: "
    "-0.020 / -0.023 / -0.026 / -0.029 / -0.032; -0.026 [-0.032, -0.020] *"
)
# need - uniform = -0.019 + 0.008 s: mean -0.003, half-width 2.7764 x 0.008 sqrt(0.5) = 0.0157.
NEED_UNIFORM = (
    "secondary: need(cosine) - uniform(plain), mean over 45-63 demos per task: "
    "-0.019 / -0.011 / -0.003 / +0.005 / +0.013; -0.003 [-0.019, +0.013]"
)


def test_the_paired_outcomes_are_the_hand_computed_ones(table, stand_in, capsys):
    lines = printed(table, capsys, str(stand_in)).splitlines()
    assert PRIMARY in lines and UNIFORM_BC in lines and NEED_UNIFORM in lines
    assert "Reading (run.sh): need is behind the best BC (the interval is below 0)" in lines
    assert "need: cosine (this study)" in lines
    assert "uniform: plain (../beyond-plateau-eval's runs, not repeated)" in lines
    assert "| need(cosine) | 33 | 0.850 | 0.850 | 0.850 | 0.850 | 0.850 | 0.850 |" in lines
    assert "| uniform(plain) | 45 | 0.920 | 0.922 | 0.924 | 0.926 | 0.928 | 0.924 |" in lines
    assert "| best BC (cosine) | 45 | 0.930 | 0.940 | 0.950 | 0.960 | 0.970 | 0.950 |" in lines


def test_a_missing_seed_or_an_unfinished_window_is_not_finished_not_a_partial_number(table, stand_in, capsys):
    (stand_in / "cosine-seed3" / "results.csv").unlink()
    write_results(
        stand_in / "cosine-seed2" / "results.csv", dagger_rows("need", 2, need_success, last_round=19)
    )
    lines = printed(table, capsys, str(stand_in)).splitlines()
    primary = [line for line in lines if line.startswith("primary")]
    assert primary == [
        "primary (fixed in run.sh before any run): need(cosine) - best BC, mean over 45-63 demos per task: "
        "not finished (seed(s) 2, 3 without the whole window)"
    ]
    assert "Reading (run.sh): not finished" in lines
    assert any(
        line.startswith("secondary: need(cosine) - uniform(plain)") and "not finished" in line
        for line in lines
    )
    assert UNIFORM_BC in lines  # uniform's reused runs and the best BC are complete
    assert "| need(cosine) | 33 | 0.850 | 0.850 | 0.850 | - | 0.850 | not finished |" in lines


def test_the_saved_records_give_the_same_runs_as_the_results_tables(table, stand_in, tmp_path):
    records = tmp_path / "records"
    for seed in SEEDS:  # what save_compare_records.sh archives: each run's phases' training.json
        (records / f"cosine-seed{seed}").mkdir(parents=True)
        with tarfile.open(records / f"cosine-seed{seed}" / "runs-records.tar.gz", "w:gz") as tar:
            add(tar, f"./need-seed{seed}/config.json", {})
            for round_ in range(21):
                phase = {
                    "demos_per_task": [2 + 3 * round_, 4 + 3 * round_],
                    "eval": {"mean": need_success(seed, round_)},
                }
                add(tar, f"./need-seed{seed}/policies/round-{round_:03d}/training.json", phase)
    trainings = {"need": "cosine", "uniform": "plain"}
    from_records = table.study_curves(trainings, None, records)
    assert from_records == table.study_curves(trainings, stand_in, records)
    assert from_records["need"][4][63] == pytest.approx(0.947)


def add(tar: tarfile.TarFile, name: str, content: dict) -> None:
    data = json.dumps(content).encode()
    info = tarfile.TarInfo(name)
    info.size = len(data)
    tar.addfile(info, io.BytesIO(data))


def test_plain_reuses_beyond_plateau_eval_and_gives_its_measured_difference_with_the_best_bc(
    table, tmp_path, capsys
):
    (tmp_path / "decision.txt").write_text(DECIDED.format(need="plain", uniform="plain"))
    lines = printed(
        table, capsys, str(tmp_path)
    ).splitlines()  # the saved tables of both studies, as committed
    assert (  # ../beyond-plateau-best-bc/table.txt's secondary: need (plain) - best BC
        "primary (fixed in run.sh before any run): need(plain) - best BC, mean over 45-63 demos per task: "
        "+0.003 / -0.017 / -0.048 / -0.001 / -0.007; -0.014 [-0.040, +0.011]"
    ) in lines
    assert any(
        line.endswith("+0.026 [+0.004, +0.048] *") for line in lines
    )  # ../beyond-plateau-eval's need - uniform


def test_the_decision_is_read_per_method(table):
    assert table.chosen_trainings(DECIDED.format(need="plateau", uniform="balanced")) == {
        "need": "plateau",
        "uniform": "balanced",
    }


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (
            DECIDED.format(need="cosine", uniform="plain").split("## uniform")[0]
            + "Decision: not yet: 3 runs unfinished (every training needs all 9).\n",
            "for uniform",
        ),
        (
            "plain check: not finished (the plain row is the reused one until it is)\n"
            + DECIDED.split("\n", 1)[1].format(need="cosine", uniform="plain"),
            "plain check",
        ),
        (DECIDED.format(need="warmup", uniform="plain"), "unknown training"),
    ],
)
def test_no_final_decision_is_refused(table, tmp_path, capsys, text, reason):
    with pytest.raises(ValueError, match=reason):
        table.chosen_trainings(text)
    (tmp_path / "decision.txt").write_text(text)
    assert table.main(["--trainings", str(tmp_path / "decision.txt")]) == 1
    assert "no final decision of ../plateau-dagger-training-dev" in capsys.readouterr().err


def run_sh(
    tmp_path: Path, dev: Path, seeds: str | None = None
) -> tuple[subprocess.CompletedProcess, list[str]]:
    """run.sh with a stand-in CLI that only notes its arguments; returns the result and the calls."""
    cli = tmp_path / "cli.sh"
    cli.write_text(f'#!/usr/bin/env bash\necho "$*" >> {tmp_path / "calls.txt"}\n')
    cli.chmod(0o755)
    (tmp_path / "calls.txt").unlink(missing_ok=True)
    environment = {**os.environ, "CLI": str(cli), "OUT": str(tmp_path / "out"), "DEV": str(dev)}
    environment.pop("SEEDS", None)
    if seeds is not None:
        environment["SEEDS"] = seeds
    result = subprocess.run(
        ["bash", str(STUDY / "run.sh")], capture_output=True, text=True, cwd=ROOT, env=environment
    )
    calls = (tmp_path / "calls.txt").read_text().splitlines() if (tmp_path / "calls.txt").exists() else []
    return result, calls


def compare_call(methods: str, seed: int, option: str, out: Path, training: str) -> str:
    return (
        f"compare --methods=[{methods}] --seeds=[{seed}] --jobs=1 --preset=small --dagger.rounds=20 "
        f"--rollout.eval_episodes=20 --progress=false {option} --output_dir={out}/{training}-seed{seed}"
    )


def write_dev(folder: Path) -> None:
    """A finished development study: need best under cosine, uniform under plateau, plain check equal."""
    plain = ROOT / "experiments" / "beyond-plateau-dev" / "report" / "results.csv"
    with plain.open() as handle:
        reused = [row for row in csv.DictReader(handle) if row["seed"] == "100" and row["bc"] == "False"]
    (folder / "plain-check").mkdir(parents=True)
    with (folder / "plain-check" / "results.csv").open("w", newline="") as handle:
        writer = csv.DictWriter(handle, fieldnames=list(reused[0]))
        writer.writeheader()
        writer.writerows(reused)
    best = {"need": "cosine", "uniform": "plateau"}
    for training in ("balanced", "cosine", "plateau"):
        rows = [
            (method, False, seed, round_, 0.99 if best[method] == training else 0.5)
            for method in ("need", "uniform")
            for seed in (100, 101, 102)
            for round_ in (10, 14, 20)
        ]
        write_results(folder / training / "results.csv", rows)


def test_run_sh_refuses_to_start_before_the_development_study_has_decided(tmp_path):
    result, calls = run_sh(tmp_path, tmp_path / "no-runs-yet")
    assert result.returncode == 1 and calls == []
    assert "finish ../plateau-dagger-training-dev first" in result.stdout
    assert "no 'Decision: the best training of ...' line for need and uniform" in result.stderr
    assert list((tmp_path / "out").iterdir()) == []  # no decision.txt, no leftover


def test_run_sh_writes_the_decision_once_and_runs_each_chosen_training(tmp_path):
    write_dev(tmp_path / "dev")
    result, calls = run_sh(tmp_path, tmp_path / "dev")
    assert result.returncode == 0, result.stderr
    out = tmp_path / "out"
    expected = []
    for seed in SEEDS:
        expected.append(compare_call("need", seed, "--training.lr_schedule=cosine", out, "cosine"))
        expected.append(compare_call("uniform", seed, "--training.steps_rule=plateau", out, "plateau"))
    assert calls == expected
    decision = (out / "decision.txt").read_text()
    assert "Decision: the best training of need is cosine." in decision
    assert "Decision: the best training of uniform is plateau." in decision
    shutil.rmtree(tmp_path / "dev")  # later runs read decision.txt alone, and never rewrite it
    result, calls = run_sh(tmp_path, tmp_path / "dev", seeds="3")
    assert result.returncode == 0, result.stderr
    assert calls == [
        compare_call("need", 3, "--training.lr_schedule=cosine", out, "cosine"),
        compare_call("uniform", 3, "--training.steps_rule=plateau", out, "plateau"),
    ]
    assert (out / "decision.txt").read_text() == decision


@pytest.mark.parametrize(
    ("need", "uniform", "expected"),
    [
        ("balanced", "balanced", ["need,uniform"]),  # one compare for both
        ("plain", "plain", []),  # nothing to run: ../beyond-plateau-eval's runs
    ],
)
def test_run_sh_with_a_saved_decision(tmp_path, need, uniform, expected):
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "decision.txt").write_text(DECIDED.format(need=need, uniform=uniform))
    result, calls = run_sh(tmp_path, tmp_path / "no-dev", seeds="0 4")
    assert result.returncode == 0, result.stderr
    option = "--training.sampling=balanced"
    out = tmp_path / "out"
    assert calls == [compare_call(m, s, option, out, "balanced") for s in (0, 4) for m in expected]
