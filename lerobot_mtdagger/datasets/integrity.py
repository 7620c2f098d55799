"""Checksums of committed files: a committed round or policy is immutable, and this proves it.

At commit every file of a round dataset or policy folder, but the file holding the record, is
hashed into the record; ``verify`` and every resume name a truncated, garbled, deleted or added one.
"""

from __future__ import annotations

import hashlib
from collections.abc import Collection, Mapping
from pathlib import Path

CHUNK_BYTES = 1 << 20


def file_sha256(path: Path) -> str:
    """The hex sha256 of a file's bytes."""
    digest = hashlib.sha256()
    with Path(path).open("rb") as handle:
        while chunk := handle.read(CHUNK_BYTES):
            digest.update(chunk)
    return digest.hexdigest()


def folder_digests(folder: Path, exclude: Collection[str] = ()) -> dict[str, str]:
    """sha256 of every file under ``folder`` but ``exclude``, by its relative POSIX path, sorted."""
    folder = Path(folder)
    files = sorted(p for p in folder.rglob("*") if p.is_file())
    relative = [(p.relative_to(folder).as_posix(), p) for p in files]
    return {name: file_sha256(path) for name, path in relative if name not in exclude}


def digest_mismatches(
    folder: Path, recorded: Mapping[str, str], exclude: Collection[str] = (), added_ok: bool = False
) -> list[str]:
    """One message per file of ``folder`` missing, changed or not in ``recorded`` (path -> sha256).

    ``exclude``: paths not hashed; ``added_ok``: files not recorded are fine (a Hub download adds some).
    """
    folder = Path(folder)
    present = folder_digests(folder, exclude)
    problems = [
        f"{folder / name} is missing (deleted after commit)" for name in recorded if name not in present
    ]
    problems += [
        f"{folder / name} changed after commit (sha256 {present[name][:12]}..., committed {digest[:12]}...)"
        for name, digest in recorded.items()
        if name in present and present[name] != digest
    ]
    if not added_ok:
        problems += [f"{folder / name} was added after commit" for name in present if name not in recorded]
    return problems
