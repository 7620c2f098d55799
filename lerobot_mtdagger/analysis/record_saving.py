"""Saving runs' records for a study: copied out of ``outputs/`` and compacted into byte-stable archives.

A run's records are its small JSON files (``SavedRunRecords``): its numbers without frames or
weights. ``save_runs`` copies them, ``compact`` packs saved runs into one ``runs-records.tar.gz``
(the same bytes for the same files), ``save_compares`` saves a study's compare folders.
"""

from __future__ import annotations

import gzip
import io
import logging
import shutil
import tarfile
import tempfile
from pathlib import Path

from lerobot_mtdagger.analysis.saved_records import ARCHIVE_NAME
from lerobot_mtdagger.datasets.experiment_dir import (
    INFO_FILE,
    RECORD_FILE,
    SAVED_INFO_FILE,
    SAVED_RECORD_FILE,
)
from lerobot_mtdagger.datasets.experiment_files import CONFIG_FILE
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

RESULTS_TABLE = "results.csv"
"""A compare folder's table of its runs."""


def run_record_files(run: Path) -> dict[str, Path]:
    """A run's record files, by their path in the saved copy."""
    files = {CONFIG_FILE: run / CONFIG_FILE}
    for round_dir in sorted(run.glob("rounds/round-*")):
        record, info = round_dir / RECORD_FILE, round_dir / INFO_FILE
        if record.is_file():
            files[f"rounds/{round_dir.name}/{SAVED_RECORD_FILE}"] = record
        elif info.is_file():
            files[f"rounds/{round_dir.name}/{SAVED_INFO_FILE}"] = info
    for phase_dir in sorted(run.glob("policies/round-*")):
        training = phase_dir / "training.json"
        if training.is_file():
            files[f"policies/{phase_dir.name}/training.json"] = training
    return files


def save_runs(runs: Path, dest: Path) -> list[str]:
    """Copies the records of every run under ``runs`` into ``dest/<run>/`` (each replaced whole); their names.

    Raises:
        UserError: If ``runs`` is not a folder of runs.
    """
    if not runs.is_dir():
        raise UserError(f"records: {runs} is not a folder: give a folder of run folders (a compare's runs/).")
    names = []
    for run in sorted(p for p in runs.iterdir() if (p / CONFIG_FILE).is_file()):
        target = dest / run.name
        shutil.rmtree(target, ignore_errors=True)
        for name, source in run_record_files(run).items():
            (target / name).parent.mkdir(parents=True, exist_ok=True)
            shutil.copyfile(source, target / name)
        names.append(run.name)
    logger.info("Saved the records of %d runs from %s into %s", len(names), runs, dest)
    return names


def stable_archive(folder: Path, members: list[str]) -> bytes:
    """A gzipped tar of ``members`` under ``folder``, the same bytes on every machine and day."""
    paths = sorted({m for member in members for m in _with_contents(folder, member)})
    buffer = io.BytesIO()
    with tarfile.open(fileobj=buffer, mode="w", format=tarfile.GNU_FORMAT) as tar:
        for name in paths:
            path = folder / name
            info = tar.gettarinfo(str(path), arcname=name)
            info.mtime, info.uid, info.gid, info.uname, info.gname = 0, 0, 0, "", ""
            info.mode = 0o644 if path.is_file() else 0o755
            if path.is_file():
                with path.open("rb") as handle:
                    tar.addfile(info, handle)
            else:
                tar.addfile(info)
    packed = io.BytesIO()
    with gzip.GzipFile(filename="", mode="wb", fileobj=packed, mtime=0) as archive:
        archive.write(buffer.getvalue())
    return packed.getvalue()


def _with_contents(folder: Path, member: str) -> list[str]:
    """``member`` and, for a folder, everything under it (relative to ``folder``)."""
    path = folder / member
    below = sorted(p.relative_to(folder).as_posix() for p in path.rglob("*")) if path.is_dir() else []
    return [member, *below]


def compact_folder(folder: Path) -> Path:
    """Packs every subfolder of ``folder`` into ``folder/runs-records.tar.gz`` and removes them.

    Raises:
        UserError: If the archive exists, or lacks a file of the subfolders (nothing is removed).
    """
    archive = folder / ARCHIVE_NAME
    if archive.exists():
        raise UserError(f"records: {archive} exists: not overwritten (move it away to compact again).")
    subfolders = sorted(p.name for p in folder.iterdir() if p.is_dir())
    staged = archive.with_name(ARCHIVE_NAME + ".tmp")
    staged.write_bytes(stable_archive(folder, subfolders))
    want = sorted(
        p.relative_to(folder).as_posix() for s in subfolders for p in (folder / s).rglob("*") if p.is_file()
    )
    with tarfile.open(staged) as tar:
        have = sorted(m.name for m in tar.getmembers() if m.isfile())
    if want != have:
        raise UserError(f"records: {staged} does not list every file of {folder}: nothing removed.")
    staged.replace(archive)
    for name in subfolders:
        shutil.rmtree(folder / name)
    logger.info("%s: %d files", archive, len(want))
    return archive


def _holds_runs(folder: Path) -> bool:
    """Whether ``folder`` has a subfolder with a run's ``config.json``."""
    return any((p / CONFIG_FILE).is_file() for p in folder.iterdir() if p.is_dir())


def compact(root: Path) -> list[Path]:
    """Archives a study's records: ``root`` if it holds runs, else each subfolder that does (the archives)."""
    if not root.is_dir():
        raise UserError(f"records: {root} is not a folder: give a study's records folder.")
    if _holds_runs(root):
        return [compact_folder(root)]
    return [compact_folder(sub) for sub in sorted(root.iterdir()) if sub.is_dir() and _holds_runs(sub)]


def save_compares(outputs: Path, dest: Path) -> list[str]:
    """Saves each compare folder under ``outputs`` into ``dest/<folder>/``; one line each on what was kept.

    Archived runs ``outputs`` no longer holds stay; where the archive then holds runs the folder did not
    run, its ``results.csv`` is not saved (``report --records`` tabulates every archived run).
    """
    if not outputs.is_dir():
        raise UserError(f"records: {outputs} is not a folder: give a study's outputs folder (outputs/STUDY).")
    lines = []
    for compare in sorted(p for p in outputs.iterdir() if (p / "runs").is_dir()):
        lines.append(_save_compare(compare, dest / compare.name))
    return lines


def _save_compare(compare: Path, dest: Path) -> str:
    """Saves one compare folder (see :func:`save_compares`) and says what it kept."""
    archive = dest / ARCHIVE_NAME
    with tempfile.TemporaryDirectory(prefix="mtdagger-save-") as stage_name:
        stage = Path(stage_name)
        if archive.is_file():
            with tarfile.open(archive) as tar:
                tar.extractall(stage, filter="data")
        save_runs(compare / "runs", stage)
        runs = sorted(p.name for p in stage.iterdir() if (p / CONFIG_FILE).is_file())
        kept = [name for name in runs if not (compare / "runs" / name / CONFIG_FILE).is_file()]
        dest.mkdir(parents=True, exist_ok=True)
        archive.write_bytes(stable_archive(stage, runs))
    table = dest / RESULTS_TABLE
    if kept:
        table.unlink(missing_ok=True)
        return (
            f"{dest}: kept the archived runs {' '.join(kept)} (not in {compare}); {RESULTS_TABLE} not saved: "
            f"lerobot-mtdagger report --records={dest} makes the table of every run"
        )
    if (compare / RESULTS_TABLE).is_file():
        shutil.copyfile(compare / RESULTS_TABLE, table)
    return f"{dest}: {len(runs)} runs"
