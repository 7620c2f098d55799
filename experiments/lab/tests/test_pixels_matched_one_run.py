"""``pixels-matched-eval/one_run.sh``: run.sh's gate, then one of its runs with its options, once."""

from __future__ import annotations

import io
import json
import os
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest
from test_pixels_matched_eval import ROOT, STUDY, compare_call, write_dev


def one_run(
    tmp_path: Path, dev: Path, *args: str, override: Path | None = None
) -> tuple[subprocess.CompletedProcess, list[str]]:
    """one_run.sh with a stand-in CLI and save step that note their calls; the result and the calls.

    ``override`` is the deviation file it reads (default: one that does not exist, so that the
    committed ``gate-deviation.md`` does not act on the stand-in gates).
    """
    calls = tmp_path / "calls.txt"
    calls.unlink(missing_ok=True)
    cli = tmp_path / "cli.sh"
    cli.write_text(f'#!/usr/bin/env bash\necho "$*" >> {calls}\n')
    cli.chmod(0o755)
    environment = {
        **os.environ,
        "CLI": str(cli),
        "PY": sys.executable,
        "OUT": str(tmp_path / "out"),
        "DEV": str(dev),
        "DEV_BC": str(tmp_path / "bc" / "results.csv"),
        "RECORDS": str(tmp_path / "records"),
        "SAVE": f"touch {tmp_path / 'saved'}",
        "OVERRIDE": str(override or tmp_path / "no-deviation.md"),
    }
    result = subprocess.run(
        ["bash", str(STUDY / "one_run.sh"), *args], capture_output=True, text=True, cwd=ROOT, env=environment
    )
    return result, calls.read_text().splitlines() if calls.exists() else []


def test_the_call_is_run_sh_compare_on_one_method_and_seed(tmp_path):
    result, calls = one_run(tmp_path, write_dev(tmp_path, 0.8, 0.7), "need", "1")  # the rerun proposed
    assert result.returncode == 0, result.stdout + result.stderr
    assert calls == [compare_call(1, tmp_path / "out").replace("[uniform,need,gain]", "[need]")]
    assert (tmp_path / "saved").exists()
    assert (tmp_path / "out" / "decision.txt").is_file()


def test_a_negative_gate_runs_nothing(tmp_path):
    result, calls = one_run(tmp_path, write_dev(tmp_path, 0.7, 0.7), "gain", "0")  # the preset stays fixed
    assert result.returncode == 0, result.stderr
    assert calls == [] and not (tmp_path / "saved").exists()
    assert "gain-seed0 not run: not run: matched training did not help" in result.stdout


@pytest.fixture
def deviation(tmp_path: Path) -> Path:
    """A stand-in for gate-deviation.md (one_run.sh reads only that it exists)."""
    path = tmp_path / "gate-deviation.md"
    path.write_text("why\n")
    return path


def test_the_deviation_runs_only_the_switch_whose_rerun_was_not_proposed(tmp_path, deviation):
    dev = write_dev(tmp_path, 0.7, 0.6)  # +0.100 over fixed, -0.100 to BC: the switch, no rerun proposed
    result, calls = one_run(tmp_path, dev, "need", "1")
    assert result.returncode == 0 and calls == [], result.stderr
    assert "need-seed1 not run: not run: matched training did not help" in result.stdout
    result, calls = one_run(tmp_path, dev, "need", "1", override=deviation)
    assert result.returncode == 0, result.stderr
    assert calls == [compare_call(1, tmp_path / "out").replace("[uniform,need,gain]", "[need]")]
    assert "runs despite the gate's answer" in result.stdout and str(deviation) in result.stdout
    assert "a pixels-eval rerun is not proposed" in (tmp_path / "out" / "decision.txt").read_text()


def test_the_deviation_does_not_run_a_preset_that_stays_fixed(tmp_path, deviation):
    result, calls = one_run(tmp_path, write_dev(tmp_path, 0.7, 0.7), "gain", "0", override=deviation)
    assert result.returncode == 0 and calls == [], result.stderr
    assert "gain-seed0 not run: not run: matched training did not help" in result.stdout


def test_the_deviation_does_not_run_before_a_final_decision(tmp_path, deviation):
    result, calls = one_run(tmp_path, tmp_path / "no-runs-yet", "uniform", "2", override=deviation)
    assert result.returncode == 1 and calls == []


def test_no_decision_yet_refuses(tmp_path):
    result, calls = one_run(tmp_path, tmp_path / "no-runs-yet", "uniform", "2")
    assert result.returncode == 1 and calls == []
    assert "has not decided by its rule yet" in result.stdout


def add(tar: tarfile.TarFile, name: str, content: dict) -> None:
    data = json.dumps(content).encode()
    info = tarfile.TarInfo(name)
    info.size = len(data)
    tar.addfile(info, io.BytesIO(data))


@pytest.mark.parametrize(("evaluated", "skipped"), [(True, True), (False, False)])
def test_a_run_archived_with_its_evaluated_phase_5_is_skipped(tmp_path, evaluated, skipped):
    (tmp_path / "records" / "seed0").mkdir(parents=True)
    with tarfile.open(tmp_path / "records" / "seed0" / "runs-records.tar.gz", "w:gz") as tar:
        add(tar, "./need-seed0/config.json", {})
        add(
            tar,
            "./need-seed0/policies/round-005/training.json",
            {"round": 5, **({"eval": {}} if evaluated else {})},
        )
    result, calls = one_run(tmp_path, write_dev(tmp_path, 0.8, 0.7), "need", "0")
    assert result.returncode == 0, result.stderr
    assert ("skipped" in result.stdout) is skipped and (calls == []) is skipped


def test_an_unknown_method_is_refused_by_name(tmp_path):
    result, calls = one_run(tmp_path, write_dev(tmp_path, 0.8, 0.7), "bc", "0")
    assert result.returncode == 2 and calls == []
    assert "METHOD must be uniform, need or gain" in result.stderr
