"""``pixels-dagger-epochs-dev/one_run.sh``: one of run.sh's runs, its options, skipped once saved."""

from __future__ import annotations

import json
import re
import shutil
import subprocess
from pathlib import Path

import pytest

STUDY = Path(__file__).resolve().parents[2] / "pixels-dagger-epochs-dev"


def compares(script: Path) -> tuple[str, dict[str, str]]:
    """The ``COMMON`` options (whitespace folded) and each arm's own compare options, as written."""
    text = script.read_text()
    common = re.search(r"^COMMON=\((.*?)\)$", text, flags=re.S | re.M).group(1)
    arms = re.findall(r'"\$CLI" compare "\$\{COMMON\[@\]\}" (.*?--output_dir="\$OUT/(\w+)")', text)
    return " ".join(common.split()), {arm: options for options, arm in arms}


def test_each_arm_runs_run_sh_compare_on_one_seed():
    common, arms = compares(STUDY / "run.sh")
    one_common, one_arms = compares(STUDY / "one_run.sh")
    assert set(arms) == {"epochs", "fixed"} and one_arms == arms
    assert one_common == common.replace("--seeds='[100,101,102]'", '--seeds="[$SEED]"')


@pytest.fixture
def study_copy(tmp_path):
    """one_run.sh in a stand-in repository (study folder two levels down), with a compare that logs."""
    study = tmp_path / "experiments" / "pixels-dagger-epochs-dev"
    study.mkdir(parents=True)
    for name in ("one_run.sh", "save_records.sh"):
        shutil.copy(STUDY / name, study / name)
    (tmp_path / "scripts").mkdir()
    shutil.copy(STUDY.parents[1] / "scripts" / "save_run_records.sh", tmp_path / "scripts")
    fake = tmp_path / "fake-cli"
    fake.write_text('#!/usr/bin/env bash\necho "$@" >> "$(dirname "$0")/cli-calls"\n')
    fake.chmod(0o755)
    return tmp_path, study


def one_run(root: Path, study: Path, *args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        ["bash", str(study / "one_run.sh"), *args],
        cwd=root,
        env={"PATH": "/usr/bin:/bin", "CLI": str(root / "fake-cli")},
        capture_output=True,
        text=True,
    )


def test_a_run_whose_records_hold_phase_5_is_skipped(study_copy):
    root, study = study_copy
    last = study / "records" / "fixed" / "uniform-seed100" / "policies" / "round-005"
    last.mkdir(parents=True)
    (last / "training.json").write_text(json.dumps({"round": 5, "eval": {"success": [0.5]}}))
    result = one_run(root, study, "fixed", "100")
    assert result.returncode == 0 and "skipped" in result.stdout
    assert not (root / "cli-calls").exists()


def test_an_unfinished_run_is_run_on_its_seed_only(study_copy):
    root, study = study_copy
    last = study / "records" / "epochs" / "uniform-seed101" / "policies" / "round-003"
    last.mkdir(parents=True)
    (last / "training.json").write_text(json.dumps({"round": 3, "eval": {"success": [0.5]}}))
    result = one_run(root, study, "epochs", "101")
    assert result.returncode == 0, result.stderr
    call = (root / "cli-calls").read_text()
    assert "--seeds=[101]" in call and "--training.steps_rule=epochs" in call
    assert "--output_dir=outputs/pixels-dagger-epochs-dev/epochs" in call


def test_an_unknown_arm_is_refused_by_name(study_copy):
    root, study = study_copy
    result = one_run(root, study, "cosine", "100")
    assert result.returncode == 2 and "ARM must be epochs or fixed" in result.stderr
    assert not (root / "cli-calls").exists()


def test_a_run_cut_before_its_last_evaluation_is_run_again(study_copy):
    root, study = study_copy
    last = study / "records" / "fixed" / "uniform-seed102" / "policies" / "round-005"
    last.mkdir(parents=True)
    (last / "training.json").write_text(json.dumps({"round": 5, "steps": 1500}))
    result = one_run(root, study, "fixed", "102")
    assert result.returncode == 0, result.stderr
    assert "--seeds=[102]" in (root / "cli-calls").read_text()
