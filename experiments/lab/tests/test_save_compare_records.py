"""``scripts/save_compare_records.sh`` (the ``records`` command): a save keeps the runs an earlier save
archived and outputs/ lost."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tarfile
from pathlib import Path

import pytest

REPO = Path(__file__).resolve().parents[3]
STUDY = "stand-in-study"


@pytest.fixture
def repository(tmp_path):
    """A stand-in repository root with the two scripts, an outputs/ and an experiments/."""
    (tmp_path / "scripts").mkdir()
    for name in ("save_compare_records.sh", "save_run_records.sh"):
        shutil.copy(REPO / "scripts" / name, tmp_path / "scripts" / name)
    return tmp_path


def write_run(runs: Path, name: str, phases: int) -> None:
    """A run folder as compare leaves it (config and each phase's training.json; frames left out)."""
    (runs / name).mkdir(parents=True)
    (runs / name / "config.json").write_text(json.dumps({"name": name}))
    for phase in range(phases):
        folder = runs / name / "policies" / f"round-{phase:03d}"
        folder.mkdir(parents=True)
        (folder / "training.json").write_text(json.dumps({"round": phase, "eval": {"mean": 0.5}}))
        (folder / "model.safetensors").write_bytes(b"weights")


def save(root: Path) -> subprocess.CompletedProcess:
    env = {**os.environ, "PYTHON": sys.executable, "PYTHONPATH": str(REPO)}  # the stand-in has no .venv
    result = subprocess.run(
        ["bash", "scripts/save_compare_records.sh", STUDY], cwd=root, capture_output=True, text=True, env=env
    )
    assert result.returncode == 0, result.stderr
    return result


def archived(root: Path) -> dict[str, list[str]]:
    """Each archived run's phases with a training.json; and no weights anywhere."""
    archive = root / "experiments" / STUDY / "records" / "seed0" / "runs-records.tar.gz"
    with tarfile.open(archive) as tar:
        names = [Path(member.name) for member in tar.getmembers() if member.isfile()]
    assert not [name for name in names if name.suffix == ".safetensors"]
    runs: dict[str, list[str]] = {}
    for name in names:
        if name.name == "training.json":
            runs.setdefault(name.parts[-4], []).append(name.parts[-2])
    return {run: sorted(phases) for run, phases in runs.items()}


def test_a_later_session_keeps_the_runs_an_earlier_one_saved(repository):
    compare = repository / "outputs" / STUDY / "seed0"
    write_run(compare / "runs", "uniform-seed0", 6)
    write_run(compare / "runs", "need-seed0", 2)  # cut by the stop
    (compare / "results.csv").write_text("method\nuniform\n")
    save(repository)
    first = archived(repository)
    assert first == {
        "uniform-seed0": [f"round-{k:03d}" for k in range(6)],
        "need-seed0": ["round-000", "round-001"],
    }
    assert (repository / "experiments" / STUDY / "records" / "seed0" / "results.csv").is_file()

    shutil.rmtree(repository / "outputs")  # a new machine: need restarted from nothing and finished
    write_run(compare / "runs", "need-seed0", 6)
    (compare / "results.csv").write_text("method\nneed\n")
    result = save(repository)

    runs = archived(repository)
    assert runs["uniform-seed0"] == first["uniform-seed0"]
    assert runs["need-seed0"] == [f"round-{k:03d}" for k in range(6)]
    assert "kept the archived runs uniform-seed0" in result.stdout
    assert not (repository / "experiments" / STUDY / "records" / "seed0" / "results.csv").exists()


def test_saving_the_same_outputs_twice_gives_the_same_bytes(repository):
    write_run(repository / "outputs" / STUDY / "seed0" / "runs", "uniform-seed0", 3)
    save(repository)
    archive = repository / "experiments" / STUDY / "records" / "seed0" / "runs-records.tar.gz"
    first = archive.read_bytes()
    save(repository)
    assert archive.read_bytes() == first
