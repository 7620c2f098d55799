"""``pixels-matched-eval``: its gate on the development study, its runs and its table, on stand-ins.

Nothing runs: run.sh gets a stand-in CLI that only notes its arguments and stand-in outputs of
``pixels-dagger-epochs-dev`` (read by that study's own table.py); table.py gets stand-in records of this
study and of ``pixels-eval``.
"""

from __future__ import annotations

import copy
import csv
import importlib.util
import io
import json
import os
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[3]
STUDY = ROOT / "experiments" / "pixels-matched-eval"
PIXELS_EVAL_ARCHIVE = ROOT / "experiments" / "pixels-eval" / "records" / "runs-records.tar.gz"
TASKS = ["a-v3", "b-v3", "c-v3", "d-v3"]
DEV_SEEDS = (100, 101, 102)
SEEDS = (0, 1, 2)
METHODS = ("uniform", "need", "gain")
NOT_RUN = "not run: matched training did not help by ../pixels-dagger-epochs-dev's rule"


@pytest.fixture(scope="module")
def table():
    spec = importlib.util.spec_from_file_location("pixels_matched_eval_table", STUDY / "table.py")
    module = importlib.util.module_from_spec(spec)
    sys.modules[spec.name] = module  # its dataclasses resolve their annotations through it
    spec.loader.exec_module(module)
    yield module
    del sys.modules[spec.name]


# ---------------------------------------------------------------- run.sh and its gate


def write_compare(folder: Path, method: str, rows: list[tuple[int, float, list[float]]]) -> None:
    """A compare folder's results.csv (``(seed, demos per task, per-task success)`` rows) and meta."""
    folder.mkdir(parents=True, exist_ok=True)
    (folder / "results_meta.json").write_text(json.dumps({"task_names": TASKS}))
    with (folder / "results.csv").open("w", newline="") as handle:
        writer = csv.writer(handle)
        writer.writerow(["method", "seed", "demos_per_task_mean", "eval_success"])
        for seed, demos, per_task in rows:
            writer.writerow([method, seed, demos, json.dumps(per_task)])


def write_dev(tmp_path: Path, epochs_60: float, fixed_60: float, seeds=DEV_SEEDS) -> Path:
    """Stand-in outputs of the development study (both arms' compares) and its balanced BC (0.8 at 60)."""
    dev = tmp_path / "dev"
    shutil.rmtree(dev, ignore_errors=True)
    for arm, last in (("epochs", epochs_60), ("fixed", fixed_60)):
        rows = [(s, demos, [value] * 4) for s in seeds for demos, value in ((10.0, 0.5), (60.0, last))]
        write_compare(dev / arm, "uniform", rows)
    write_compare(tmp_path / "bc", "bc-balanced", [(s, 60.0, [0.8] * 4) for s in DEV_SEEDS])
    return dev


def run_sh(
    tmp_path: Path, dev: Path, seeds: str | None = None
) -> tuple[subprocess.CompletedProcess, list[str]]:
    """run.sh with a stand-in CLI that only notes its arguments; returns the result and the calls."""
    cli = tmp_path / "cli.sh"
    cli.write_text(f'#!/usr/bin/env bash\necho "$*" >> {tmp_path / "calls.txt"}\n')
    cli.chmod(0o755)
    (tmp_path / "calls.txt").unlink(missing_ok=True)
    environment = {
        **os.environ,
        "CLI": str(cli),
        "OUT": str(tmp_path / "out"),
        "DEV": str(dev),
        "DEV_BC": str(tmp_path / "bc" / "results.csv"),
    }
    environment.pop("SEEDS", None)
    if seeds is not None:
        environment["SEEDS"] = seeds
    result = subprocess.run(
        ["bash", str(STUDY / "run.sh")], capture_output=True, text=True, cwd=ROOT, env=environment
    )
    calls = (tmp_path / "calls.txt").read_text().splitlines() if (tmp_path / "calls.txt").exists() else []
    return result, calls


def compare_call(seed: int, out: Path) -> str:
    return (
        f"compare --methods=[uniform,need,gain] --seeds=[{seed}] --jobs=1 --preset=metaworld-pixels "
        "--rollout.eval_episodes=20 --progress=false --training.steps_rule=epochs --training.epochs=10 "
        f"--output_dir={out}/seed{seed}"
    )


def test_run_sh_refuses_while_the_development_study_has_no_outputs(tmp_path):
    result, calls = run_sh(tmp_path, tmp_path / "no-runs-yet")
    assert result.returncode == 1 and calls == []
    assert "nothing run: ../pixels-dagger-epochs-dev has not decided by its rule yet" in result.stdout
    assert list((tmp_path / "out").iterdir()) == []  # no decision.txt, no leftover


def test_run_sh_refuses_a_decision_on_fewer_than_the_three_development_seeds(tmp_path):
    result, calls = run_sh(tmp_path, write_dev(tmp_path, 0.8, 0.7, seeds=(100, 101)))
    assert result.returncode == 1 and calls == []
    assert "'primary: epochs - fixed:' rests on 2 of its 3 seeds" in result.stderr
    assert list((tmp_path / "out").iterdir()) == []


def test_run_sh_when_the_preset_stays_fixed_runs_nothing_and_keeps_that_decision(tmp_path):
    result, calls = run_sh(tmp_path, write_dev(tmp_path, 0.7, 0.7))  # epochs - fixed +0.000 < +0.03
    assert result.returncode == 0, result.stderr
    assert calls == []
    assert f"{NOT_RUN} (the preset stays fixed), so this study is not run." in result.stdout
    decision = (tmp_path / "out" / "decision.txt").read_text()
    assert "Decision: the preset stays fixed (epochs - fixed at 60 +0.000" in decision
    # Written once: a later run reads it, whatever the development outputs say by then.
    result, calls = run_sh(tmp_path, write_dev(tmp_path, 0.8, 0.7))
    assert result.returncode == 0 and calls == []
    assert NOT_RUN in result.stdout
    assert (tmp_path / "out" / "decision.txt").read_text() == decision


def test_run_sh_when_the_switch_proposes_no_rerun_runs_nothing(tmp_path):
    result, calls = run_sh(tmp_path, write_dev(tmp_path, 0.7, 0.6))  # +0.100 over fixed, -0.100 to BC
    assert result.returncode == 0, result.stderr
    assert calls == []
    assert (
        f"{NOT_RUN} (the DAgger phases switch to epochs, but epochs' phase 5 is more than 0.02"
        in result.stdout
    )
    assert "a pixels-eval rerun is not proposed" in (tmp_path / "out" / "decision.txt").read_text()


def test_run_sh_when_the_rerun_is_proposed_runs_each_seed_as_fixed(tmp_path):
    result, calls = run_sh(tmp_path, write_dev(tmp_path, 0.8, 0.7))  # +0.100 over fixed, level with BC
    assert result.returncode == 0, result.stderr
    out = tmp_path / "out"
    assert calls == [compare_call(seed, out) for seed in SEEDS]
    assert "run: ../pixels-dagger-epochs-dev switches the DAgger phases to epochs" in result.stdout
    decision = (out / "decision.txt").read_text()
    assert (
        "Decision: the preset's DAgger phases switch to epochs (10 passes); epochs - BC at 60 +0.000: "
        "a pixels-eval rerun is proposed"
    ) in decision
    shutil.rmtree(tmp_path / "dev")  # later runs read decision.txt alone, and never rewrite it
    result, calls = run_sh(tmp_path, tmp_path / "dev", seeds="2")
    assert result.returncode == 0, result.stderr
    assert calls == [compare_call(2, out)]
    assert (out / "decision.txt").read_text() == decision


@pytest.mark.parametrize(
    ("text", "reason"),
    [
        (
            "primary: epochs - fixed: fewer than 2 seeds have both\n\nDecision: none yet (no seed ...).\n",
            "0 of",
        ),
        ("primary: epochs - fixed: +0.1 / +0.1 / +0.1; +0.100 [+0.1, +0.1] *\n", "0 'Decision:' lines"),
        (
            "primary: epochs - fixed: +0.1 / +0.1 / +0.1; +0.1\nDecision: something else.\n",
            "unknown decision",
        ),
        (
            "primary: epochs - fixed: +0.1 / +0.1 / +0.1; +0.1\nepochs - balanced BC: +0.0 / +0.0; +0.0\n"
            "Decision: the preset's DAgger phases switch to epochs (10 passes); epochs - BC at 60 +0.000: "
            "a pixels-eval rerun is proposed (...).\n",
            "rests on 2 of 3 seeds",
        ),
    ],
)
def test_no_final_decision_is_refused(table, tmp_path, capsys, text, reason):
    with pytest.raises(table.NotDecidedError, match=reason):
        table.gate(text)
    (tmp_path / "decision.txt").write_text(text)
    assert table.main(["--gate", str(tmp_path / "decision.txt")]) == 1
    assert "no final decision of ../pixels-dagger-epochs-dev yet" in capsys.readouterr().err


# ---------------------------------------------------------------- table.py on stand-in records

# Four tasks a-d. pixels-eval's stand-in uniform phase 0 is [0.1, 0.2, 0.3, 0.9] on every seed, so its
# rule's 3 hardest tasks are a, b, c; this study's phase 0 is [0.9, 0.2, 0.3, 0.1] (its own would be d, b,
# c). This study's phases 1-5 score [h, h, h, 1.0]; BC scores [hb, hb, hb, 1.0] at 20-50 demos per task
# and [hb + 0.06] x 3 + [0.82] at 60 (the same mean); pixels-eval's DAgger phases 1-5 [0.1, 0.1, 0.1, 1.0].
HARD = {  # seed -> h (hardest tasks' success at 60) per arm; BC: hb
    "need": (0.40, 0.44, 0.48),
    "uniform": (0.32, 0.36, 0.36),
    "gain": (0.24, 0.40, 0.44),
    "bc": (0.36, 0.48, 0.52),
}
PASSES = [12.0, 8.0, 6.0, 14.0]

# By hand: a list [h, h, h, 1.0] has mean 0.25 + 0.75 h, so over 20-60 demos per task need 0.55 / 0.58 /
# 0.61, uniform 0.49 / 0.52 / 0.52, gain 0.43 / 0.55 / 0.58, BC 0.52 / 0.61 / 0.64 (seeds 0 / 1 / 2).
# 95% t interval over 3 seeds: mean +- 4.3027 sd / sqrt(3).
# need - BC: +0.03 / -0.03 / -0.03, mean -0.010, sd 0.0346, half-width 0.0861.
# need - uniform: +0.06 / +0.06 / +0.09, mean +0.070, sd 0.0173, half-width 0.0430.
# gain - BC: -0.09 / -0.06 / -0.06, mean -0.070, half-width 0.0430.
# gain - uniform: -0.06 / +0.03 / +0.06, mean +0.010, sd 0.0624, half-width 0.1551.
# At 60 on a, b, c: need - uniform h differences +0.08 / +0.08 / +0.12 (mean +0.0933, sd 0.0231,
# half-width 0.0574); gain - uniform -0.08 / +0.04 / +0.08 (mean +0.0133, sd 0.0833, half-width 0.2068);
# need - BC h - (hb + 0.06): -0.02 / -0.10 / -0.10 (mean -0.0733, sd 0.0462, half-width 0.1147);
# uniform - BC -0.10 / -0.18 / -0.22 (mean -0.1667, sd 0.0611, half-width 0.1518).
OUTCOMES = [
    "primary: need - BC, mean success over 20-60 demos per task: +0.030 / -0.030 / -0.030; "
    "-0.010 [-0.096, +0.076]",
    "  reading: inconclusive (the interval holds 0 and reaches +0.05 or more)",
    "primary: need - uniform, mean success over 20-60 demos per task: +0.060 / +0.060 / +0.090; "
    "+0.070 [+0.027, +0.113] *",
    "  reading: reproduced (the interval is above 0)",
    "secondary: gain - BC, mean success over 20-60 demos per task: -0.090 / -0.060 / -0.060; "
    "-0.070 [-0.113, -0.027] *",
    "  reading: reversed (the interval is below 0, under matched training)",
    "secondary: gain - uniform, mean success over 20-60 demos per task: -0.060 / +0.030 / +0.060; "
    "+0.010 [-0.145, +0.165]",
    "secondary: need - uniform, the 3 hardest tasks of each seed at 60 demos per task: "
    "+0.080 / +0.080 / +0.120; +0.093 [+0.036, +0.151] *",
    "secondary: gain - uniform, the 3 hardest tasks of each seed at 60 demos per task: "
    "-0.080 / +0.040 / +0.080; +0.013 [-0.194, +0.220]",
    "secondary (added here): need - BC, the 3 hardest tasks of each seed at 60 demos per task: "
    "-0.020 / -0.100 / -0.100; -0.073 [-0.188, +0.041]",
    "  reading: not reproduced (the interval holds 0 and lies below +0.05)",
    "secondary (added here): uniform - BC, the 3 hardest tasks of each seed at 60 demos per task: "
    "-0.100 / -0.180 / -0.220; -0.167 [-0.318, -0.015] *",
]
# pixels-eval's need - BC: 0.325 against 0.52 / 0.61 / 0.64, mean -0.265, sd 0.0624, half-width 0.1551.
EARLIER_NEED_BC = (
    "  earlier protocol (pixels-eval, 1 500 fixed steps per phase): -0.195 / -0.285 / -0.315; "
    "-0.265 [-0.420, -0.110] *"
)
DECIDED = (
    "primary: epochs - fixed: +0.100 / +0.100 / +0.100; +0.100 [+0.100, +0.100] *\n"
    "epochs - balanced BC: +0.000 / +0.000 / +0.000; +0.000 [+0.000, +0.000]\n\n"
    "Decision: the preset's DAgger phases switch to epochs (10 passes); epochs - BC at 60 +0.000: a "
    "pixels-eval rerun is proposed (epochs - fixed at 60 +0.100, needs >= +0.03; epochs phase 0 0.500, "
    "phase 5 0.800).\n"
)


def template_config() -> dict:
    """A BC run's config.json as pixels-eval stored it (its committed records)."""
    with tarfile.open(PIXELS_EVAL_ARCHIVE) as tar:
        return json.load(tar.extractfile("bc-60demos-seed1/config.json"))


def config(template: dict, name: str, seed: int, matched: bool) -> dict:
    """``template`` for run ``name``; matched: this study's options (an option added since at its default)."""
    values = copy.deepcopy(template)
    values.update(output_dir=f"runs/{name}", seed=seed, mode="bc" if name.startswith("bc") else "dagger")
    values["scheduler"]["type"] = name.split("-")[0]
    if matched:
        values["training"].update(steps_rule="epochs", epochs=10.0, seed=None)
    return values


def phase(round_: int, per_task: list[float], steps: int = 1000) -> dict:
    """A phase's training.json: 6 400 frames per round of data, passes PASSES, losses by hand."""
    frames = 6400 * (round_ + 1)
    return {
        "round": round_,
        "trained_on_rounds": list(range(round_ + 1)),
        "frames": frames,
        "steps": steps * (round_ + 1),
        "gain_split": "train",
        "loss_start": [1.0, 2.0, 3.0, 4.0] if round_ == 0 else [9.0] * 4,
        "loss_end": [0.5, 1.0, 1.5, 2.0] if round_ == 0 else [0.3, 0.6, 0.9, 1.2],
        "gain": None,
        "loss_samples": [64] * 4,
        "final_train_loss": [0.1] * 4,
        "eval": {
            "task_names": TASKS,
            "success": per_task,
            "episodes": [20] * 4,
            "mean": float(np.mean(per_task)),
        },
        "demos_per_task": [10 * (round_ + 1)] * 4,
        "timings": {},
        "loss_previous": None if round_ == 0 else [0.6, 1.2, 1.8, 2.4],
        "passes_per_task": PASSES,
    }


def write_run(folder: Path, run_config: dict, phases: list[dict]) -> None:
    folder.mkdir(parents=True)
    (folder / "config.json").write_text(json.dumps(run_config))
    for record in phases:
        path = folder / "policies" / f"round-{record['round']:03d}" / "training.json"
        path.parent.mkdir(parents=True)
        path.write_text(json.dumps(record))


def hard_list(h: float) -> list[float]:
    return [h, h, h, 1.0]


def write_pixels_eval(folder: Path, template: dict) -> Path:
    """pixels-eval's stand-in records: BC at 10-60 demos per task and the DAgger runs, seeds 0-2."""
    for seed in SEEDS:
        hb = HARD["bc"][seed]
        for demos in (10, 20, 30, 40, 50, 60):
            per_task = {10: [0.5] * 4, 60: [round(hb + 0.06, 2)] * 3 + [0.82]}.get(demos, hard_list(hb))
            name = f"bc-{demos}demos-seed{seed}"
            record = phase(0, per_task, steps=150 * demos) | {"frames": 640 * demos, "passes_per_task": None}
            write_run(folder / name, config(template, name, seed, matched=False), [record])
        for method in METHODS:
            name = f"{method}-seed{seed}"
            phases = [phase(0, [0.1, 0.2, 0.3, 0.9], steps=1500)]
            phases += [phase(r, hard_list(0.1), steps=1500 // (r + 1)) for r in range(1, 6)]
            write_run(folder / name, config(template, name, seed, matched=False), phases)
    return folder


def write_study(out: Path, template: dict) -> Path:
    """This study's stand-in runs in ``out/seed<k>/runs/`` and its decision."""
    out.mkdir(parents=True, exist_ok=True)
    (out / "decision.txt").write_text(DECIDED)
    for seed in SEEDS:
        for method in METHODS:
            name = f"{method}-seed{seed}"
            phases = [phase(0, [0.9, 0.2, 0.3, 0.1])] + [
                phase(r, hard_list(HARD[method][seed])) for r in range(1, 6)
            ]
            write_run(out / f"seed{seed}" / "runs" / name, config(template, name, seed, matched=True), phases)
    return out


@pytest.fixture
def stand_in(table, tmp_path, monkeypatch):
    template = template_config()
    monkeypatch.setattr(table, "PIXELS_EVAL_RECORDS", write_pixels_eval(tmp_path / "pixels-eval", template))
    monkeypatch.setattr(table, "RECORDS", tmp_path / "records")
    return write_study(tmp_path / "out", template)


def printed(table, capsys, *argv: str) -> list[str]:
    assert table.main(list(argv)) == 0
    return capsys.readouterr().out.splitlines()


def test_the_outcomes_are_the_hand_computed_ones_beside_the_earlier_protocol(table, stand_in, capsys):
    lines = printed(table, capsys, str(stand_in))
    missing = [line for line in OUTCOMES if line not in lines]
    assert missing == []
    assert EARLIER_NEED_BC in lines
    primary = lines.index(OUTCOMES[0])
    assert lines[primary + 2] == EARLIER_NEED_BC  # beside its own outcome
    assert lines.count("  reading: inconclusive (the interval holds 0 and reaches +0.05 or more)") == 3
    assert (
        "BC reuse check (pixels-eval's BC configs, today's metaworld-pixels preset, this study's runs): holds"
        in lines
    )
    assert (
        "Hardest tasks (pixels-eval's rule on its uniform phase 0): "
        "seed 0 a, b, c; seed 1 a, b, c; seed 2 a, b, c"
    ) in lines
    assert (
        "| need, matched (epochs, 10 passes per phase) | 0.375 | 0.580 | 0.580 | 0.580 | 0.580 | 0.580 |"
        in lines
    )
    assert "| BC (pixels-eval's runs, reused) | 0.500 | 0.590 | 0.590 | 0.590 | 0.590 | 0.590 |" in lines


def test_the_passes_and_loss_tables(table, stand_in, capsys):
    lines = printed(table, capsys, str(stand_in))
    # 6 400 frames and 1 000 steps of 64 per round of data: 10 passes over all frames; per task PASSES.
    assert (
        "| uniform | 0 | 0 | 10 | 6400 | 1000 | 10.00 | 10.00 [6.00-14.00] | a 12.00, b 8.00, c 6.00 |"
        in lines
    )
    assert (
        "| gain | 2 | 5 | 60 | 38400 | 6000 | 10.00 | 10.00 [6.00-14.00] | a 12.00, b 8.00, c 6.00 |" in lines
    )
    # pixels-eval's passes over all frames: phase k 1 500 steps x 64 / (6 400 x (k + 1)) = 15 / (k + 1);
    # BC at d demos per task 150 d steps x 64 / (640 d frames) = 15.
    assert "| need | 1 | 15.00 | 7.50 | 5.00 | 3.75 | 3.00 | 2.50 |" in lines
    assert "| BC | 2 | 15.00 | 15.00 | 15.00 | 15.00 | 15.00 | 15.00 |" in lines
    # Loss before: loss_start in phase 0, loss_previous after; loss after: loss_end.
    assert "| need | 1 | 0 | 1 -> 0.5 | 2 -> 1 | 3 -> 1.5 | 4 -> 2 |" in lines
    assert "| need | 1 | 3 | 0.6 -> 0.3 | 1.2 -> 0.6 | 1.8 -> 0.9 | 2.4 -> 1.2 |" in lines
    rows = [line for line in lines if line.startswith(tuple(f"| {m} |" for m in METHODS)) and " -> " in line]
    assert len(rows) == 3 * 3 * 6  # every phase of every run


def test_a_missing_run_or_phase_gives_not_finished_not_a_partial_number(table, stand_in, capsys):
    for round_ in (4, 5):
        shutil.rmtree(stand_in / "seed2" / "runs" / "need-seed2" / "policies" / f"round-{round_:03d}")
    shutil.rmtree(stand_in / "seed1" / "runs" / "gain-seed1")
    lines = printed(table, capsys, str(stand_in))
    outcome_lines = [line for line in lines if line.startswith(("primary", "secondary"))]
    assert len(outcome_lines) == 8
    assert all(
        line.endswith(": not finished (missing: need seed 2 (phases 4, 5); gain seed(s) 1)")
        for line in outcome_lines
    )
    assert lines.count("  reading: not finished") == 8
    assert EARLIER_NEED_BC in lines  # pixels-eval's numbers stay: they are complete
    assert (
        "| need, matched (epochs, 10 passes per phase) | 0.375 | 0.580 | 0.580 | 0.580 | "
        "not finished | not finished |"
    ) in lines


def test_the_saved_archives_give_what_the_outputs_give(table, stand_in, tmp_path, capsys):
    records = tmp_path / "records"
    for seed in SEEDS:  # as scripts/save_compare_records.sh archives a compare folder's runs
        (records / f"seed{seed}").mkdir(parents=True)
        with tarfile.open(records / f"seed{seed}" / "runs-records.tar.gz", "w:gz") as tar:
            for path in sorted((stand_in / f"seed{seed}" / "runs").rglob("*.json")):
                data = path.read_bytes()
                info = tarfile.TarInfo("./" + str(path.relative_to(stand_in / f"seed{seed}" / "runs")))
                info.size = len(data)
                tar.addfile(info, io.BytesIO(data))
    shutil.copy(stand_in / "decision.txt", records / "decision.txt")
    from_records = printed(table, capsys)
    assert from_records == printed(table, capsys, str(stand_in))
    assert OUTCOMES[2] in from_records


def test_a_changed_training_fails_the_bc_reuse_check_and_blocks_the_bc_outcomes(table, stand_in, capsys):
    path = stand_in / "seed1" / "runs" / "need-seed1" / "config.json"
    changed = json.loads(path.read_text())
    changed["training"]["sampling"] = "uniform"
    path.write_text(json.dumps(changed))
    lines = printed(table, capsys, str(stand_in))
    assert any(
        line.startswith("BC reuse check")
        and "FAILS: need-seed1 differs from BC: training.sampling: 'uniform' ('balanced')" in line
        for line in lines
    )
    assert (
        "primary: need - BC, mean success over 20-60 demos per task: "
        "not read: the BC reuse check fails (above)"
    ) in lines
    assert OUTCOMES[2] in lines  # need - uniform does not involve BC


def test_the_real_bc_configs_pass_and_the_earlier_protocol_is_pixels_eval_table(table, tmp_path, capsys):
    (tmp_path / "decision.txt").write_text(DECIDED)
    lines = printed(table, capsys, str(tmp_path))  # no run of this study yet; pixels-eval's committed records
    assert any(line.startswith("BC reuse check") and line.endswith(": holds") for line in lines)
    earlier = [line for line in lines if line.startswith("  earlier protocol")]
    committed = (ROOT / "experiments" / "pixels-eval" / "table.txt").read_text().splitlines()
    for name in ("need - bc", "need - uniform", "gain - bc", "gain - uniform"):
        numbers = next(line for line in committed if line.startswith(f"{name}: ")).split(": ", 1)[1]
        assert any(line.endswith(numbers) for line in earlier[:4]), name
    assert (
        "Hardest tasks (pixels-eval's rule on its uniform phase 0): seed 0 push, pick-place, "
        "peg-insert-side; seed 1 pick-place, peg-insert-side, push; seed 2 pick-place, push, reach"
    ) in lines


def test_a_negative_or_missing_decision(table, tmp_path, capsys):
    assert printed(table, capsys, str(tmp_path)) == [
        f"No decision yet: {tmp_path / 'decision.txt'} does not exist (run.sh writes it once "
        "../pixels-dagger-epochs-dev has decided)."
    ]
    stays = (
        DECIDED.split("Decision:")[0] + "Decision: the preset stays fixed (epochs - fixed at 60 +0.010).\n"
    )
    (tmp_path / "decision.txt").write_text(stays)
    lines = printed(table, capsys, str(tmp_path))
    assert lines[-1].startswith(f"Verdict: {NOT_RUN} (the preset stays fixed), so this study is not run.")


NOT_PROPOSED = DECIDED.replace("a pixels-eval rerun is proposed", "a pixels-eval rerun is not proposed")


def test_runs_made_by_the_gate_deviation_are_reported_with_it(table, stand_in, tmp_path, capsys, monkeypatch):
    """The gate proposed no rerun, the runs ran by gate-deviation.md: the outcomes, each marked."""
    (stand_in / "decision.txt").write_text(NOT_PROPOSED)
    deviation = tmp_path / "gate-deviation.md"
    deviation.write_text("why\n")
    monkeypatch.setattr(table, "DEVIATION", deviation)
    lines = printed(table, capsys, str(stand_in))
    assert lines[1].startswith(f"Gate (run.sh, pre-specified): {NOT_RUN} (the DAgger phases switch to epochs")
    assert "(gate-deviation.md); every reading below carries it." in lines[2]
    marked = " [run by the gate deviation, gate-deviation.md]"
    assert [line for line in OUTCOMES if line.startswith("primary")] == [
        line for line in lines if line.startswith("primary")
    ]
    assert f"  reading: reproduced (the interval is above 0){marked}" in lines
    readings = [line for line in lines if line.startswith("  reading: ")]
    assert len(readings) == 8 and all(line.endswith(marked) for line in readings)


def test_without_the_deviation_file_the_gate_stands(table, stand_in, tmp_path, capsys, monkeypatch):
    (stand_in / "decision.txt").write_text(NOT_PROPOSED)
    monkeypatch.setattr(table, "DEVIATION", tmp_path / "no-such-file.md")
    lines = printed(table, capsys, str(stand_in))
    assert lines[-1].startswith(f"Verdict: {NOT_RUN} (the DAgger phases switch to epochs")
    assert not any(line.startswith("primary") for line in lines)


def test_a_run_on_both_cores_passes_the_bc_reuse_check(table, stand_in, capsys):
    """`compare` gives a run on two cores 2 env workers, which change no result (tests/test_workers.py)."""
    path = stand_in / "seed2" / "runs" / "gain-seed2" / "config.json"
    on_two_cores = json.loads(path.read_text())
    on_two_cores["rollout"]["workers"] = 2
    path.write_text(json.dumps(on_two_cores))
    lines = printed(table, capsys, str(stand_in))
    assert any(line.startswith("BC reuse check") and line.endswith(": holds") for line in lines)
    assert OUTCOMES[0] in lines
