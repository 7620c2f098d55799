"""Paths probed before a command does any work, so a bad one is refused in one line, up front.

Outputs are probed for being writable (``check_output_dir``, ``check_output_file``), inputs for being
there (``check_input_path``).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

from lerobot_mtdagger.utils.errors import UserError


def _nearest_existing(path: Path) -> Path:
    """``path`` itself or its nearest ancestor that exists."""
    probe = path.absolute()
    while not probe.exists() and probe != probe.parent:
        probe = probe.parent
    return probe


def _writable(folder: Path) -> bool:
    """Whether a file can be created in ``folder``, probed for real (``os.access`` lies for root)."""
    try:
        with tempfile.TemporaryFile(dir=folder):
            return True
    except OSError:
        return False


def check_output_dir(path: Path | str, option: str) -> None:
    """Refuses a folder that cannot be created or written, with a ValueError naming ``option`` and the fix."""
    path = Path(path)
    if path.exists() and not path.is_dir():
        raise ValueError(f"{option}={path} is a file: give a folder path.")
    _check_creatable(path, option)


def check_output_file(path: Path | str, option: str) -> None:
    """Refuses a file path that cannot be written, with a ValueError naming ``option`` and the fix."""
    path = Path(path)
    if path.is_dir():
        raise ValueError(f"{option}={path} is a folder: give a file path.")
    if path.exists() and not os.access(path, os.W_OK):
        raise ValueError(f"{option}={path} cannot be written (read-only file); choose another path.")
    _check_creatable(path.parent, option, shown=path)


def _check_creatable(folder: Path, option: str, shown: Path | None = None) -> None:
    """Refuses a folder whose nearest existing ancestor is a file or cannot be written into."""
    shown = folder if shown is None else shown
    existing = _nearest_existing(folder)
    if not existing.is_dir():
        raise ValueError(f"{option}={shown} lies under the file {existing}: give a path in a folder.")
    if not _writable(existing):
        raise ValueError(
            f"{option}={shown} cannot be written: {existing} is not writable here; choose another."
        )


def check_input_path(path: Path | str, option: str, takes: str) -> None:
    """Refuses an input path that does not exist.

    Args:
        path: The file or folder a command will read.
        option: The option that gave it (``--previous``), for the message.
        takes: What the option takes, for the message ("the previous session's plan file").

    Raises:
        UserError: Naming the option, the path and what to give instead.
    """
    if not Path(path).exists():
        raise UserError(f"{option}={path} does not exist: give {takes}.")
