"""Saves what the MT50 study has made so far into git's reach, so that it outlives ``outputs/``.

Run folders live in ``outputs/``, which is not in git and goes with the machine. Before a session
stops, from the repository root:

    .venv/bin/python experiments/mt50-state-eval/snapshot.py

It writes
- ``report/``: the interim report of every committed phase (``report.md`` listing the unfinished runs,
  the figures, and the saved table ``results.csv``/``results.json``/``results_meta.json``); run.sh's
  last step overwrites it with the final report;
- ``seeds/seed<S>/``: the saved table of each seed whose runs of the main comparison (BC at every
  budget and the four DAgger methods) have all finished. If ``outputs/`` is lost, those seeds need
  not run again: compare the remaining ones and join the tables,
  ``report --results='[seeds/seed0,<new report>]' --output_dir=...``.
"""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

from lerobot_mtdagger.analysis.results import run_progress

CLI = ".venv/bin/lerobot-mtdagger"
OUT = Path("outputs/mt50-state-eval")
BALANCED = Path("outputs/mt50-state-eval-bc-balanced")
HERE = Path("experiments/mt50-state-eval")
LEVELS = "--levels=[0.6,0.8,0.9]"
SEEDS = (0, 1, 2)


def interim_report() -> None:
    """The report of every committed phase of both comparisons into ``report/``."""
    variants = [f"--variants={{bc-balanced: {BALANCED}}}"] if (BALANCED / "runs").is_dir() else []
    command = [CLI, "report", f"--compare_dir={OUT}", *variants, LEVELS, f"--output_dir={HERE / 'report'}"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)


def finished_seed_runs(seed: int) -> list[Path] | None:
    """The run folders of ``seed`` in the main comparison's plan, or None while one is unfinished."""
    plan = json.loads((OUT / "compare.json").read_text())["jobs"]
    runs = [OUT / "runs" / name for name in plan if name.endswith(f"-seed{seed}")]
    if not runs or not all(run.is_dir() and run_progress(run).finished for run in runs):
        return None
    return runs


def seed_table(seed: int, runs: list[Path]) -> None:
    """The saved table of one finished seed into ``seeds/seed<S>/`` (its report.md kept, no figure)."""
    folder = HERE / "seeds" / f"seed{seed}"
    experiments = "--experiments=[" + ",".join(str(run) for run in runs) + "]"
    command = [CLI, "report", experiments, LEVELS, f"--output_dir={folder}"]
    subprocess.run(command, check=True, stdout=subprocess.DEVNULL)
    for figure in folder.glob("*.png"):
        figure.unlink()


def main() -> int:
    """Writes the interim report and the table of every finished seed; prints what it wrote."""
    interim_report()
    print(f"interim report: {HERE / 'report'}")
    for seed in SEEDS:
        runs = finished_seed_runs(seed)
        if runs is None:
            print(f"seed {seed}: unfinished, no table of its own yet")
            continue
        seed_table(seed, runs)
        print(f"seed {seed}: finished, {len(runs)} runs saved in {HERE / 'seeds' / f'seed{seed}'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
