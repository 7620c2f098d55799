"""Runs' saved records (config, round and phase records; no frames or weights), as folders or archives.

``report --records`` reads a run's folder of records, a folder of them, or their byte-stable archive
``runs-records.tar.gz``, which is unpacked once per process into a temporary folder; its runs are named
as if unpacked beside the archive, so a table names the same runs either way.
"""

from __future__ import annotations

import atexit
import logging
import shutil
import tarfile
import tempfile
from pathlib import Path

from lerobot_mtdagger.datasets.experiment_files import CONFIG_FILE
from lerobot_mtdagger.utils.errors import UserError

logger = logging.getLogger(__name__)

ARCHIVE_NAME = "runs-records.tar.gz"
"""The archive of a folder of runs' records."""

_UNPACKED: dict[Path, tuple[Path, Path]] = {}
"""Each archive read -> (the folder it was unpacked into, the folder its runs are named in)."""


def saved_records_runs(path: Path) -> list[Path]:
    """The runs' records at ``path``: a run's folder, a folder of them (or of compare folders), or archives.

    Raises:
        UserError: If ``path`` holds no run's records, naming the commands that save them.
    """
    path = Path(path)
    if path.is_file() and path.name.endswith((".tar.gz", ".tgz", ".tar")):
        runs = _runs_in(unpack(path))
    elif (path / CONFIG_FILE).is_file():
        runs = [path]
    elif path.is_dir():
        runs = _runs_in(path)
        for archive in sorted([*path.glob(ARCHIVE_NAME), *path.glob(f"*/{ARCHIVE_NAME}")]):
            runs += _runs_in(unpack(archive))
    else:
        runs = []
    if not runs:
        raise UserError(
            f"--records: {path} holds no run's records (a config.json in it or its subfolders, or a "
            f"{ARCHIVE_NAME}): give the folder `bash scripts/save_run_records.sh RUNS DEST` wrote (DEST), "
            "one run's folder in it, or a study's records folder."
        )
    return runs


def _runs_in(folder: Path) -> list[Path]:
    """The subfolders of ``folder`` that hold a run's records."""
    return sorted(p for p in folder.iterdir() if (p / CONFIG_FILE).is_file())


def unpack(archive: Path) -> Path:
    """The folder ``archive`` is unpacked into, once per process (``UserError`` if not a tar archive)."""
    key = archive.resolve()
    if key not in _UNPACKED:
        folder = Path(tempfile.mkdtemp(prefix="mtdagger-records-"))
        atexit.register(shutil.rmtree, folder, ignore_errors=True)
        try:
            with tarfile.open(archive) as tar:
                tar.extractall(folder, filter="data")
        except (tarfile.TarError, OSError) as error:
            raise UserError(f"--records: cannot read {archive} as a tar archive ({error}).") from error
        logger.debug("Unpacked %s into %s", archive, folder)
        _UNPACKED[key] = (folder, archive.parent)
    return _UNPACKED[key][0]


def shown_name(run: Path) -> str:
    """How a run is named in tables: unpacked from an archive, as if beside the archive."""
    for folder, shown in _UNPACKED.values():
        if run.is_relative_to(folder):
            return str(shown / run.relative_to(folder))
    return str(run)
