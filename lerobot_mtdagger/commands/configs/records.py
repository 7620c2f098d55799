"""Options of ``lerobot-mtdagger records``: what to do with which runs' records, and where they go."""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

ACTIONS = ("save", "compact", "save_compares")
"""What ``--action`` may ask: save runs' records, compact a records folder, save a study's compares."""


@dataclass
class RecordsConfig:
    """Options of ``lerobot-mtdagger records``.

    Attributes:
        action: ``save`` (every run under ``--source`` into ``--dest``), ``compact`` (the records
            folder ``--source`` into byte-stable archives) or ``save_compares`` (each compare folder of
            the study outputs ``--source`` into ``--dest``, as an archive beside its results table).
        source: A folder of runs (``save``), a records folder (``compact``) or ``outputs/STUDY``
            (``save_compares``).
        dest: Where the records go (``save``, ``save_compares``), e.g. ``experiments/STUDY/records``.
    """

    action: str = "save"
    source: Path | None = None
    dest: Path | None = None

    def __post_init__(self) -> None:
        if self.action not in ACTIONS:
            raise ValueError(f"--action={self.action!r}: use one of {', '.join(ACTIONS)}.")
        if self.source is None or not Path(self.source).is_dir():
            raise ValueError(f"--source={self.source}: give an existing folder (see --help).")
        if self.action != "compact" and self.dest is None:
            raise ValueError(f"--action={self.action} needs --dest (where the records go).")
