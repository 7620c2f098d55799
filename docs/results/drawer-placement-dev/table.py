"""The drawer-placement study's table, from the runs' phase records.

    .venv/bin/python docs/results/drawer-placement-dev/table.py RUN_DIR [RUN_DIR ...]

A RUN_DIR is an experiment folder or a saved ``records/<run>`` folder (``policies/round-000/
training.json``). Prints one row per run (frames, final training loss, success on the 11 training
drawers and on the 4 unseen ones, the paper's 0-3 progress score) and then the success of each drawer.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np


def phase_record(run: Path) -> dict:
    """The BC phase's record of a run."""
    return json.loads((run / "policies" / "round-000" / "training.json").read_text())


def main(runs: list[Path]) -> None:
    """Prints the tables."""
    records = {run.name: phase_record(run) for run in runs}
    columns = ["demos/drawer", "frames", "final train loss", "success (11)", "progress", "unseen (4)"]
    print("| run | " + " | ".join([*columns, "unseen progress"]) + " |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for name, record in records.items():
        loss = float(np.mean(record["final_train_loss"]))
        unseen = record["heldout_eval"]
        print(
            f"| {name} | {record['demos_per_task'][0]} | {record['frames']} | {loss:.3f} | "
            f"{record['eval']['mean']:.3f} | {record['eval']['mean_progress']:.2f} | "
            f"{unseen['mean']:.2f} | {unseen['mean_progress']:.2f} |"
        )
    print()
    first = next(iter(records.values()))
    drawers = first["eval"]["task_names"] + first["heldout_eval"]["task_names"]
    print("| drawer | " + " | ".join(records) + " |")
    print("|---|" + "---:|" * len(records))
    for drawer in drawers:
        cells = []
        for record in records.values():
            for part in ("eval", "heldout_eval"):
                if drawer in record[part]["task_names"]:
                    cells.append(f"{record[part]['success'][record[part]['task_names'].index(drawer)]:.1f}")
        print(f"| {drawer} | " + " | ".join(cells) + " |")


if __name__ == "__main__":
    main([Path(arg) for arg in sys.argv[1:]])
