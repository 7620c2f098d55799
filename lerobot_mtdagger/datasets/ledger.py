"""The experiment's ledger: a hash chain over every committed record, so an edited number is named.

``ledger.json`` lists every round and phase record in commit order with its sha256 and the hash of
the entry before it::

    {"entries": [
      {"record": "rounds/round-000/meta/mtdagger.json", "sha256": "...", "previous": null},
      {"record": "policies/round-000/training.json", "sha256": "...", "previous": "<entry 0's hash>"},
      ...]}

``docs/reliability.md`` describes what is checked and when.
"""

from __future__ import annotations

import hashlib
import json
import logging
from collections.abc import Sequence
from pathlib import Path
from typing import Any

from lerobot_mtdagger.datasets.integrity import file_sha256

logger = logging.getLogger(__name__)

LEDGER_FILE = "ledger.json"


def entry_hash(entry: dict[str, Any]) -> str:
    """The sha256 of one entry (its canonical JSON), which the next entry names as ``previous``."""
    return hashlib.sha256(json.dumps(entry, sort_keys=True).encode()).hexdigest()


class Ledger:
    """The hash chain of the committed records of the experiment at ``root`` (it may not exist yet)."""

    def __init__(self, root: Path) -> None:
        self.root = Path(root)
        self.path = self.root / LEDGER_FILE

    def exists(self) -> bool:
        """Whether the experiment has a ledger."""
        return self.path.is_file()

    def entries(self) -> list[dict[str, Any]]:
        """The entries, in commit order ([] without a ledger; ValueError if the file is not a ledger)."""
        if not self.exists():
            return []
        try:
            entries = json.loads(self.path.read_text())["entries"]
        except (OSError, json.JSONDecodeError, KeyError, TypeError) as error:
            reason = f"{type(error).__name__}: {error}"
            raise ValueError(f"{self.path} is not a readable ledger ({reason})") from None
        return list(entries)

    def missing_tail(self, entries: Sequence[dict[str, Any]]) -> int:
        """How many of the last entries name records that no longer exist (rounds deleted to be redone)."""
        count = 0
        for entry in reversed(entries):
            if (self.root / str(entry.get("record"))).is_file():
                break
            count += 1
        return count

    def append(self, records: Sequence[Path], write: Any) -> None:
        """Adds the record files (in commit order) not listed yet, written with ``write(path, payload)``."""
        entries = self.entries()
        tail = self.missing_tail(entries)
        if tail:  # the last rounds were deleted to be redone: their entries go, and they are written anew
            logger.info("Dropping %d ledger entries of deleted records from %s", tail, self.path)
            entries = entries[: len(entries) - tail]
        kept = len(entries)
        listed = {entry["record"] for entry in entries}
        for record in records:
            name = Path(record).relative_to(self.root).as_posix()
            if name in listed:
                continue
            previous = entry_hash(entries[-1]) if entries else None
            entries.append({"record": name, "sha256": file_sha256(record), "previous": previous})
            listed.add(name)
        if tail or len(entries) > kept:  # nothing dropped or added: the file is left as it is
            write(self.path, {"entries": entries})

    def problems(self, records: Sequence[Path], deleted_tail_ok: bool = False) -> list[str]:
        """What differs between the committed records and the ledger (nothing without a ledger).

        ``deleted_tail_ok`` accepts entries at the end whose records were deleted for a resume to redo.
        """
        if not self.exists():
            return []
        try:
            entries = self.entries()
        except ValueError as error:
            return [str(error)]
        problems = []
        previous = None
        if deleted_tail_ok:
            entries = entries[: len(entries) - self.missing_tail(entries)]
        matching = 0
        for position, entry in enumerate(entries):
            if entry.get("previous") != previous:
                problems.append(f"{LEDGER_FILE}: entry {position} ({entry.get('record')}) breaks the chain")
            previous = entry_hash(entry)
            path = self.root / str(entry.get("record"))
            if not path.is_file():
                problems.append(f"{path} is in the ledger but missing (deleted after commit)")
            elif file_sha256(path) != entry.get("sha256"):
                problems.append(f"{path} changed after commit (its sha256 differs from {LEDGER_FILE})")
            else:
                matching += 1
        if entries and not matching:
            return [
                f"{self.path} was replaced: none of its {len(entries)} entries matches a record of this "
                "experiment; restore the experiment's own ledger from a copy of it"
            ]
        listed = {entry.get("record") for entry in entries}
        for record in records:
            name = Path(record).relative_to(self.root).as_posix()
            if name not in listed:
                problems.append(f"{name} is committed but not in {LEDGER_FILE} (a resume adds it)")
        return problems
