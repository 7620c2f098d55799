"""``paper-regime-training-dev/table.py`` on the study's committed records: its decisions and passes."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
STUDY = ROOT / "experiments" / "paper-regime-training-dev"


def test_the_committed_records_give_every_decision_and_every_runs_passes():
    result = subprocess.run(
        [sys.executable, str(STUDY / "table.py"), str(STUDY / "records")],
        capture_output=True,
        text=True,
        cwd=ROOT,
        env={**os.environ, "PYTHONPATH": f"{ROOT / 'experiments'}:{ROOT}"},
    )
    assert result.returncode == 0, result.stderr
    for arm in ("bc", "uniform", "need"):
        assert f"Decision: the training of {arm} is cosine." in result.stdout
    passes_rows = [
        line for line in result.stdout.splitlines() if line.startswith(("| plain | ", "| cosine | "))
    ]
    runs = {row.split(" | ")[1] for row in passes_rows}
    for seed in (100, 101):  # read from the archives: every run of both seeds, not only seed 100
        assert {f"bc-6demos-seed{seed}", f"uniform-seed{seed}", f"need-seed{seed}"} <= runs
    dagger_rows = [row for row in passes_rows if "need-seed" in row or "uniform-seed" in row]
    assert all(row.count(";") == 9 for row in dagger_rows)  # ten phases each
