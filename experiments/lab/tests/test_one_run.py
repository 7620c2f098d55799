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


def write_phase(study: Path, arm: str, seed: int, phase: int, record: dict) -> None:
    """A phase's training.json in the study's records, as save_records.sh leaves it."""
    folder = study / "records" / arm / f"uniform-seed{seed}" / "policies" / f"round-{phase:03d}"
    folder.mkdir(parents=True)
    (folder / "training.json").write_text(json.dumps({"round": phase, **record}))


@pytest.mark.parametrize(
    ("arm", "seed", "phase", "record", "skipped"),
    [
        ("fixed", 100, 5, {"eval": {"success": [0.5]}}, True),
        ("epochs", 101, 3, {"eval": {"success": [0.5]}}, False),  # unfinished
        ("fixed", 102, 5, {"steps": 1500}, False),  # cut before its last evaluation
    ],
)
def test_only_a_run_whose_records_hold_an_evaluated_phase_5_is_skipped(
    study_copy, arm, seed, phase, record, skipped
):
    root, study = study_copy
    write_phase(study, arm, seed, phase, record)
    result = one_run(root, study, arm, str(seed))
    assert result.returncode == 0, result.stderr
    assert ("skipped" in result.stdout) is skipped
    calls = (root / "cli-calls").read_text() if (root / "cli-calls").exists() else ""
    assert (calls == "") is skipped
    if not skipped:
        assert (
            f"--seeds=[{seed}]" in calls and f"--output_dir=outputs/pixels-dagger-epochs-dev/{arm}" in calls
        )
        assert ("--training.steps_rule=epochs" in calls) is (arm == "epochs")


def test_an_unknown_arm_is_refused_by_name(study_copy):
    root, study = study_copy
    result = one_run(root, study, "cosine", "100")
    assert result.returncode == 2 and "ARM must be epochs or fixed" in result.stderr
    assert not (root / "cli-calls").exists()
