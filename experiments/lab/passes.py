"""Each phase's passes over each task's frames (``passes_per_task`` in a phase's ``training.json``)."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.saved_records import ARCHIVE_NAME, saved_records_runs


def compare_runs(compare: Path) -> list[Path]:
    """The runs of one compare folder: its ``runs/`` in ``outputs/``, or its saved records' archive.

    Returns:
        The runs' folders (an archive's unpacked once per process), none if the folder has neither.
    """
    if (compare / "runs").is_dir():
        return saved_records_runs(compare / "runs")
    if (compare / ARCHIVE_NAME).is_file():
        return saved_records_runs(compare)
    return []


def phase_passes(run: Path) -> list[str]:
    """One cell per phase of ``run``: its passes over each task's frames, ``mean [min-max]`` over tasks."""
    cells = []
    for record in sorted(run.glob("policies/round-*/training.json")):
        per_task = [p for p in json.loads(record.read_text()).get("passes_per_task") or [] if p is not None]
        if per_task:
            cells.append(f"{np.mean(per_task):.0f} [{min(per_task):.0f}-{max(per_task):.0f}]")
    return cells
