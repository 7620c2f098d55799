"""``paper-regime-eval/table.py``: its settings rule and its analysis, on stand-in ``results.csv`` files."""

from __future__ import annotations

import csv
import importlib.util
import json
import operator
import shutil
from pathlib import Path

import pytest

EXPERIMENTS = Path(__file__).resolve().parents[2]
TASKS = ["a-v3", "b-v3", "c-v3", "d-v3", "e-v3", "f-v3"]
COLUMNS = [
    "experiment",
    "method",
    "bc",
    "seed",
    "round",
    "demos_per_task_mean",
    "eval_success_mean",
    "eval_success",
]


@pytest.fixture(scope="module")
def table():
    spec = importlib.util.spec_from_file_location(
        "paper_regime_eval_table", EXPERIMENTS / "paper-regime-eval" / "table.py"
    )
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def write_results(path: Path, rows: list[tuple[str, bool, int, int, float, list[float]]]) -> None:
    """``(method, bc, seed, round, demos per task, per-task success)`` rows as compare writes them."""
    path.parent.mkdir(parents=True, exist_ok=True)
    with path.open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(COLUMNS)
        for method, bc, seed, round_, demos, per_task in rows:
            mean = sum(per_task) / len(per_task)
            writer.writerow(["x", method, str(bc), seed, round_, demos, mean, json.dumps(per_task)])


def dagger_rows(method: str, seed: int, level: float, rounds: int = 9) -> list:
    return [
        (
            method,
            False,
            seed,
            r,
            3.0 + 3 * r,
            [min(1.0, level + 0.02 * r + 0.01 * t) for t in range(len(TASKS))],
        )
        for r in range(rounds + 1)
    ]


def bc_rows(seed: int, level: float, budgets=(6, 18, 30)) -> list:
    return [
        ("bc", True, seed, 0, float(b), [min(1.0, level + 0.005 * b + 0.05 * t) for t in range(len(TASKS))])
        for b in budgets
    ]


def write_dev(folder: Path, need_level: float) -> None:
    """The training study's two trainings and two seeds: cosine better for uniform only."""
    for training in ("plain", "cosine"):
        for seed in (100, 101):
            uniform = 0.5 + (0.05 if training == "cosine" else 0.0)
            rows = (
                bc_rows(seed, 0.4)
                + dagger_rows("uniform", seed, uniform)
                + dagger_rows("need", seed, need_level)
            )
            write_results(folder / f"{training}-seed{seed}" / "results.csv", rows)


def write_check(folder: Path) -> None:
    folder.mkdir(parents=True)
    (folder / "kept.txt").write_text("tasks: " + ",".join(TASKS) + "\nmap: {}\n")


def eval_folder(table, tmp_path: Path) -> Path:
    """An evaluation folder with the settings read from stand-in development results (need at 0.65)."""
    out = tmp_path / "eval"
    write_dev(tmp_path / "dev", need_level=0.65)
    write_check(tmp_path / "check")
    out.mkdir()
    (out / "settings.txt").write_text("\n".join(table.settings(tmp_path / "dev", tmp_path / "check")) + "\n")
    return out


def test_settings_follow_the_development_rules(table, tmp_path):
    write_dev(tmp_path / "dev", need_level=0.65)  # need at 30 demos: 0.65 + 0.18 + task terms >= 0.80
    write_check(tmp_path / "check")
    lines = dict(line.split(": ", 1) for line in table.settings(tmp_path / "dev", tmp_path / "check"))
    assert lines["training bc"] == "plain" and lines["training uniform"] == "cosine"
    assert lines["training gain"] == lines["training need_raw"] == lines["training need"] == "plain"
    assert lines["arms cosine"] == "uniform" and lines["arms plain"] == "bc,need,need_raw,gain"
    assert lines["rounds"] == "9" and lines["bc budgets"] == "6,12,18,24,30"
    assert lines["hardest tasks"].split(",") == TASKS[:5]  # BC's success rises with the task index


def test_need_below_the_level_on_development_seeds_means_more_rounds(table, tmp_path):
    write_dev(tmp_path / "dev", need_level=0.3)
    write_check(tmp_path / "check")
    lines = dict(line.split(": ", 1) for line in table.settings(tmp_path / "dev", tmp_path / "check"))
    assert lines["rounds"] == "12" and lines["bc budgets"].endswith(",39")


def test_settings_wait_for_every_decision(table, tmp_path):
    write_dev(tmp_path / "dev", need_level=0.65)
    (tmp_path / "dev" / "cosine-seed101" / "results.csv").unlink()
    write_check(tmp_path / "check")
    assert table.settings(tmp_path / "dev", tmp_path / "check") is None
    assert table.main(["--settings", str(tmp_path / "dev"), str(tmp_path / "check")]) == 1


def test_analysis_reports_the_primary_and_its_verdict(table, tmp_path):
    out = eval_folder(table, tmp_path)
    for seed, gap in zip((0, 1, 2), (0.04, 0.05, 0.06), strict=True):
        write_results(
            out / f"plain-seed{seed}" / "results.csv",
            bc_rows(seed, 0.4, (6, 12, 18, 24, 30)) + dagger_rows("need", seed, 0.6 + gap),
        )
        write_results(out / f"cosine-seed{seed}" / "results.csv", dagger_rows("uniform", seed, 0.6))
    text = "\n".join(table.analysis(out))
    assert "PRIMARY need - uniform (seeds [0, 1, 2]): +0.040 / +0.050 / +0.060; +0.050" in text
    assert "Verdict (run.sh's rule): reproduced" in text
    assert "need_raw - uniform: 0 seed(s) complete" in text


def test_two_seeds_decide_nothing(table, tmp_path):
    out = eval_folder(table, tmp_path)
    for seed in (0, 1):
        write_results(out / f"plain-seed{seed}" / "results.csv", dagger_rows("need", seed, 0.1))
        write_results(out / f"cosine-seed{seed}" / "results.csv", dagger_rows("uniform", seed, 0.6))
    text = "\n".join(table.analysis(out))
    assert "Verdict (run.sh's rule): not yet decided" in text


def test_a_running_compare_folder_is_read_from_its_runs(table, tmp_path):
    """Seed 0's saved runs without their ``results.csv`` (as while compare runs) give the table's rows."""
    saved = EXPERIMENTS / "paper-regime-eval" / "records" / "cosine-seed0"
    (tmp_path / "cosine-seed0").mkdir()
    shutil.copy(saved / "runs-records.tar.gz", tmp_path / "cosine-seed0")
    from_runs = table.read_rows(tmp_path)
    bc = sorted((row["demos"], round(row["success"], 3)) for row in from_runs if row["arm"] == "bc")
    assert bc == [(6.0, 0.527), (12.0, 0.65), (18.0, 0.703), (24.0, 0.816), (30.0, 0.871)]
    key = operator.itemgetter("arm", "demos")
    from_table = sorted(table.read_rows(saved.parent), key=key)
    assert [(r["arm"], r["demos"], r["success"], r["per_task"]) for r in sorted(from_runs, key=key)] == [
        (r["arm"], r["demos"], r["success"], r["per_task"]) for r in from_table if r["seed"] == 0
    ]
    assert len(from_runs) == 5 + 4 * 10 and all(len(row["per_task"]) == 43 for row in from_runs)


def test_a_curve_still_running_is_not_censored(table, tmp_path):
    out = eval_folder(table, tmp_path)
    write_results(out / "plain-seed0" / "results.csv", dagger_rows("need", 0, 0.1, rounds=5))
    write_results(out / "cosine-seed0" / "results.csv", dagger_rows("uniform", 0, 0.1))
    text = "\n".join(table.analysis(out))
    assert "  need: - / - / -" in text  # stopped at 18 demos: running, not "never reached"
    assert "  uniform: >30 / - / -" in text


def test_a_run_just_started_gives_no_row(table, tmp_path):
    """A run with its config written and no round committed yet (compare has just started it) is skipped."""
    from lerobot_mtdagger.analysis.saved_records import saved_records_runs

    saved = EXPERIMENTS / "paper-regime-eval" / "records" / "cosine-seed0"
    runs = tmp_path / "cosine-seed0" / "runs"
    for run in saved_records_runs(saved):
        shutil.copytree(run, runs / run.name)
    started = runs / "gain-seed9"
    (started / "rounds").mkdir(parents=True)
    (started / "policies").mkdir()
    shutil.copy(runs / "gain-seed0" / "config.json", started / "config.json")
    rows = table.read_rows(tmp_path)
    assert len(rows) == 5 + 4 * 10 and {row["seed"] for row in rows} == {0}
