"""``analysis.record_saving``: a study's run records saved, compacted byte-stably, and read back."""

from __future__ import annotations

import json
import os
import shutil
import tarfile

import pytest

from lerobot_mtdagger.analysis.record_saving import compact, save_compares, save_runs
from lerobot_mtdagger.analysis.saved_records import saved_records_runs
from lerobot_mtdagger.utils.errors import UserError


def write_run(runs, name, phases=2, success=0.5):
    """A run folder with the files a run writes: its records and heavier files that are not saved.

    Round 0 is as a round written before ``meta/mtdagger.json`` existed (its record only in info.json).
    """
    run = runs / name
    (run / "policies").mkdir(parents=True)
    (run / "config.json").write_text(json.dumps({"name": name}))
    (run / "run.log").write_text("log\n")
    for k in range(phases):
        meta = run / "rounds" / f"round-{k:03d}" / "meta"
        meta.mkdir(parents=True)
        (meta / "info.json").write_text(json.dumps({"round": k}))
        if k > 0:
            (meta / "mtdagger.json").write_text(json.dumps({"round": k}))
        (meta.parent / "data.parquet").write_bytes(b"frames")
        phase = run / "policies" / f"round-{k:03d}"
        phase.mkdir()
        (phase / "training.json").write_text(json.dumps({"eval": {"mean": success}}))
        (phase / "model.safetensors").write_bytes(b"weights")
    return run


def files_under(folder):
    return sorted(p.relative_to(folder).as_posix() for p in folder.rglob("*") if p.is_file())


def test_saving_copies_only_the_records_and_replaces_a_run_whole(tmp_path):
    runs, dest = tmp_path / "runs", tmp_path / "dest"
    write_run(runs, "need-seed0", phases=2)
    save_runs(runs, dest)
    assert files_under(dest) == [
        "need-seed0/config.json",
        "need-seed0/policies/round-000/training.json",
        "need-seed0/policies/round-001/training.json",
        "need-seed0/rounds/round-000/info.json",  # older: the record is in info.json only
        "need-seed0/rounds/round-001/mtdagger.json",  # the record, not the dataset's info
    ]
    (dest / "other-seed1").mkdir()
    (dest / "other-seed1" / "config.json").write_text("{}")
    shutil.rmtree(runs / "need-seed0")
    write_run(runs, "need-seed0", phases=1)  # restarted from nothing
    save_runs(runs, dest)
    assert not (dest / "need-seed0" / "policies" / "round-001").exists()
    assert (dest / "other-seed1" / "config.json").is_file()  # a run not under runs keeps its records


def test_compacting_gives_the_same_bytes_for_the_same_files_and_reads_back(tmp_path):
    archives = []
    for copy in ("a", "b"):
        records = tmp_path / copy / "records"
        save_runs(write_run(tmp_path / copy / "runs", "bc-6demos-seed0").parent, records)
        os.utime(records / "bc-6demos-seed0" / "config.json", (1_000 * len(archives), 1_000 * len(archives)))
        (written,) = compact(records)
        archives.append(written)
        assert files_under(records) == ["runs-records.tar.gz"]
    assert archives[0].read_bytes() == archives[1].read_bytes()
    (run,) = saved_records_runs(archives[0].parent)
    assert json.loads((run / "policies" / "round-001" / "training.json").read_text())["eval"]["mean"] == 0.5


def test_compacting_never_overwrites_an_archive(tmp_path):
    records = tmp_path / "records"
    save_runs(write_run(tmp_path / "runs", "need-seed0").parent, records)
    (records / "runs-records.tar.gz").write_bytes(b"kept")
    with pytest.raises(UserError, match="exists: not overwritten"):
        compact(records)
    assert (records / "runs-records.tar.gz").read_bytes() == b"kept"
    assert (records / "need-seed0" / "config.json").is_file()


def test_saving_a_study_keeps_archived_runs_and_then_leaves_its_table_out(tmp_path):
    outputs, dest = tmp_path / "outputs" / "study", tmp_path / "records"
    compare = outputs / "cosine-seed0"
    write_run(compare / "runs", "need-seed0")
    write_run(compare / "runs", "uniform-seed0")
    (compare / "results.csv").write_text("table\n")
    assert save_compares(outputs, dest) == [f"{dest / 'cosine-seed0'}: 2 runs"]
    assert (dest / "cosine-seed0" / "results.csv").read_text() == "table\n"
    shutil.rmtree(compare / "runs" / "uniform-seed0")  # a machine that kept no outputs/
    (line,) = save_compares(outputs, dest)
    assert "kept the archived runs uniform-seed0" in line
    assert not (dest / "cosine-seed0" / "results.csv").exists()
    with tarfile.open(dest / "cosine-seed0" / "runs-records.tar.gz") as tar:
        assert {"need-seed0/config.json", "uniform-seed0/config.json"} <= set(tar.getnames())


def test_a_missing_folder_is_one_clear_refusal(tmp_path):
    with pytest.raises(UserError, match="is not a folder"):
        save_runs(tmp_path / "nowhere", tmp_path / "dest")
    with pytest.raises(UserError, match="outputs/STUDY"):
        save_compares(tmp_path / "nowhere", tmp_path / "dest")


def test_the_records_command_saves_and_compacts_and_refuses_in_one_line(tmp_path):
    import subprocess
    import sys

    def records(*options):
        command = [sys.executable, "-m", "lerobot_mtdagger.cli", "records", *options]
        return subprocess.run(command, capture_output=True, text=True, check=False)

    write_run(tmp_path / "runs", "need-seed0")
    saved = records("--action=save", f"--source={tmp_path / 'runs'}", f"--dest={tmp_path / 'records'}")
    assert saved.returncode == 0, saved.stderr
    compacted = records("--action=compact", f"--source={tmp_path / 'records'}")
    assert compacted.returncode == 0 and files_under(tmp_path / "records") == ["runs-records.tar.gz"]
    refused = records("--action=save", f"--source={tmp_path / 'nowhere'}", "--dest=x")
    assert refused.returncode == 2 and len(refused.stderr.strip().splitlines()) == 1
    assert "give an existing folder" in refused.stderr
