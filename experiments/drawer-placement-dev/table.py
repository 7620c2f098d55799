"""The drawer-placement study's table, from the runs' phase records.

    .venv/bin/python experiments/drawer-placement-dev/table.py RUN_DIR [RUN_DIR ...]

A RUN_DIR is an experiment folder or a saved ``records/<run>`` folder (``policies/round-000/
training.json``). Prints one row per run (frames, final training loss, success on the 11 training
drawers and on the 4 unseen ones, the paper's 0-3 progress score), the success of each drawer, and
once ``run-epochs.sh``'s kitchen runs at 10 and 60 demos exist for seeds 100-102, its decision by the
rule fixed in that script (a line starting ``Decision:``).
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np


def phase_record(run: Path) -> dict:
    """The BC phase's record of a run."""
    return json.loads((run / "policies" / "round-000" / "training.json").read_text())


EPOCHS_RUN = re.compile(r"^bc-epochs-kitchen-(?P<demos>\d+)demos-seed(?P<seed>\d+)$")
DECISION_SEEDS = (100, 101, 102)
DECISION_TOLERANCE = 0.02


def epochs_decision(records: dict[str, dict]) -> str | None:
    """``run-epochs.sh``'s decision line, or None while a kitchen run at 10 or 60 demos is missing.

    The drawer evaluation-seed study trains BC with ``--training.steps_rule=epochs`` if kitchen BC's
    mean success over seeds 100-102 at 60 demos is at least its mean at 10 demos minus 0.02.
    """
    success: dict[tuple[int, int], float] = {}
    for name, record in records.items():
        match = EPOCHS_RUN.match(name)
        if match:
            success[(int(match["demos"]), int(match["seed"]))] = record["eval"]["mean"]
    if any((demos, seed) not in success for demos in (10, 60) for seed in DECISION_SEEDS):
        return None
    at_10 = float(np.mean([success[(10, seed)] for seed in DECISION_SEEDS]))
    at_60 = float(np.mean([success[(60, seed)] for seed in DECISION_SEEDS]))
    keeps = at_60 >= at_10 - DECISION_TOLERANCE
    verdict = "epochs (no loss with more data)" if keeps else "none yet (try the plateau rule)"
    return f"Decision: BC steps {verdict}: kitchen mean at 60 demos {at_60:.3f}, at 10 demos {at_10:.3f}"


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
    decision = epochs_decision(records)
    if decision is not None:
        print(f"\n{decision}")


if __name__ == "__main__":
    main([Path(arg) for arg in sys.argv[1:]])
