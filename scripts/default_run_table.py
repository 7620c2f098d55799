"""The default run's table in ``docs/dagger.md``, regenerated from an experiment folder.

Usage (from the repository root)::

    .venv/bin/lerobot-mtdagger run --progress=false --output_dir=/tmp/default-run
    .venv/bin/python scripts/default_run_table.py /tmp/default-run --write

Without ``--write`` it prints the table. With it, the table replaces the one between the
``default-run`` markers of ``docs/dagger.md`` and the numbers it was made from go to
``docs/data/default-run.json``; ``tests/test_docs_numbers.py`` checks that the page holds the table
that file gives, so the page quotes what a run of the code gave, never a number typed by hand.
"""

from __future__ import annotations

import argparse
import json
import platform
import subprocess
import sys
from pathlib import Path
from typing import Any

from lerobot_mtdagger.datasets.experiment_dir import ExperimentDir

ROOT = Path(__file__).resolve().parents[1]
PAGE = ROOT / "docs" / "dagger.md"
RECORD = ROOT / "docs" / "data" / "default-run.json"
START = "<!-- default-run: scripts/default_run_table.py -->\n"
END = "\n<!-- /default-run -->"


def read_run(folder: Path) -> dict[str, Any]:
    """Each round's episodes per task and the evaluation success per task after its phase."""
    experiment = ExperimentDir(folder)
    rounds = experiment.committed_rounds()
    phases = [experiment.read_phase_record(index) for index in rounds]
    records = [experiment.read_round_record(index) for index in rounds]
    return {
        "tasks": list(phases[0].eval["task_names"]),
        "episodes": [list(record.episodes_per_task) for record in records],
        "success": [list(phase.eval["success"]) for phase in phases],
        "mean": [phase.eval["mean"] for phase in phases],
    }


def table(run: dict[str, Any]) -> str:
    """The markdown table: a row per task, then the mean success after each round."""
    rounds = range(len(run["episodes"]))
    head = [f"r{k} eps" for k in rounds] + [f"eval after r{k}" for k in rounds]
    lines = ["| task | " + " | ".join(head) + " |", "|---" * (len(head) + 1) + "|"]
    for i, task in enumerate(run["tasks"]):
        cells = [str(run["episodes"][k][i]) for k in rounds] + [f"{run['success'][k][i]:.1f}" for k in rounds]
        lines.append(f"| {task} | " + " | ".join(cells) + " |")
    means = [""] * len(rounds) + [f"**{mean:.2f}**" for mean in run["mean"]]
    lines.append("| **mean eval success** | " + " | ".join(means) + " |")
    return "\n".join(lines)


def provenance() -> dict[str, str]:
    """The commit, Python and machine the run was made on."""
    commit = subprocess.run(
        ["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True, check=True
    ).stdout.strip()
    return {"commit": commit, "python": platform.python_version(), "machine": platform.machine()}


def write(run: dict[str, Any]) -> None:
    """Puts the table into the page and the numbers into the record."""
    page = PAGE.read_text()
    if START not in page or END not in page:
        sys.exit(f"{PAGE} has no default-run markers ({START.strip()} ... {END.strip()}): add them first")
    before, rest = page.split(START, 1)
    after = rest.split(END, 1)[1]
    PAGE.write_text(before + START + table(run) + END + after)
    RECORD.parent.mkdir(parents=True, exist_ok=True)
    RECORD.write_text(json.dumps({**run, "made_with": provenance()}, indent=1) + "\n")


def main() -> None:
    """Reads the run folder and prints or writes its table."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("folder", type=Path, help="the default run's experiment folder")
    parser.add_argument("--write", action="store_true", help="update docs/dagger.md and its record")
    args = parser.parse_args()
    run = read_run(args.folder)
    if args.write:
        write(run)
    else:
        print(table(run))


if __name__ == "__main__":
    main()
