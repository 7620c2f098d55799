"""A finished study's report regenerates from its compacted records (``records/runs-records.tar.gz``)."""

from __future__ import annotations

import csv
import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
STUDY = ROOT / "experiments" / "pixels-eval"


def rows_without_folder(path: Path) -> list[dict]:
    """A results table's rows, each run named by its own folder only (the study moved since)."""
    with path.open() as handle:
        rows = list(csv.DictReader(handle))
    for row in rows:
        row["experiment"] = Path(row["experiment"]).name
    return rows


def test_pixels_eval_report_regenerates_from_its_archive(tmp_path):
    assert (STUDY / "records" / "runs-records.tar.gz").is_file()
    command = [
        sys.executable,
        "-m",
        "lerobot_mtdagger.cli",
        "report",
        f"--records=[{STUDY / 'records'}]",
        "--levels=[0.6,0.7]",
        f"--output_dir={tmp_path}",
    ]
    result = subprocess.run(
        command, capture_output=True, text=True, cwd=ROOT, env={**os.environ, "MPLBACKEND": "Agg"}
    )
    assert result.returncode == 0, result.stderr
    assert rows_without_folder(tmp_path / "results.csv") == rows_without_folder(
        STUDY / "report" / "results.csv"
    )
    assert (tmp_path / "report.md").read_text() == (STUDY / "report" / "report.md").read_text()
