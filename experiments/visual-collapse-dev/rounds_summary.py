"""What each round dataset of a drawer run holds: frames, long episodes, and the expert's labels.

    .venv/bin/python experiments/visual-collapse-dev/rounds_summary.py outputs/visual-dev/NAME-seedS [...]

Per round: episodes, frames, the share of episodes (and of frames) from episodes that ran the full
300-step horizon, the share of frames labelled "open the gripper" (gripper command < 0), the mean
|z| command, and each phase's evaluation success and final training loss. Then per phase the success
of every training drawer and, where the run evaluated them, of every unseen drawer.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pyarrow as pa
import pyarrow.parquet as pq

HORIZON = 300


def round_numbers(root: Path) -> dict[str, float]:
    """The label and length statistics of one round dataset."""
    table = pa.concat_tables(
        [pq.read_table(p, columns=["action", "episode_index"]) for p in sorted(root.glob("data/*/*.parquet"))]
    )
    actions = np.array(table.column("action").to_pylist(), dtype=np.float32)
    episodes = table.column("episode_index").to_numpy()
    lengths = np.bincount(episodes)[np.unique(episodes)]
    long = lengths >= HORIZON
    return {
        "episodes": int(len(lengths)),
        "frames": int(len(actions)),
        "long_episodes": float(long.mean()),
        "long_frames": float(lengths[long].sum() / lengths.sum()),
        "open_labels": float((actions[:, 3] < 0).mean()),
        "mean_abs_z": float(np.abs(actions[:, 2]).mean()),
    }


def main(folders: list[str]) -> None:
    """Prints one table per experiment folder."""
    for folder in map(Path, folders):
        print(f"\n{folder}")
        print(
            "| round | episodes | frames | 300-step episodes | their frames | 'open' labels | mean abs z "
            "| eval success after | final train loss |"
        )
        print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|")
        for root in sorted((folder / "rounds").glob("round-*")):
            k = int(root.name.split("-")[1])
            n = round_numbers(root)
            phase_file = folder / "policies" / root.name / "training.json"
            success, loss = "n/a", "n/a"
            if phase_file.exists():
                phase = json.loads(phase_file.read_text())
                success = f"{phase['eval']['mean']:.3f}" if phase.get("eval") else "n/a"
                loss = f"{np.mean(phase['final_train_loss']):.3f}"
            print(
                f"| {k} | {n['episodes']} | {n['frames']} | {n['long_episodes']:.2f} "
                f"| {n['long_frames']:.2f} "
                f"| {n['open_labels']:.2f} | {n['mean_abs_z']:.2f} | {success} | {loss} |"
            )
        print_per_drawer(folder)


def print_per_drawer(folder: Path) -> None:
    """Success per drawer (and per unseen drawer) after each phase of one run."""
    phases = [json.loads(p.read_text()) for p in sorted(folder.glob("policies/round-*/training.json"))]
    for key, title in (("eval", "training drawers"), ("heldout_eval", "unseen drawers")):
        evaluated = [phase[key] for phase in phases if phase.get(key)]
        if not evaluated:
            continue
        print(f"\nsuccess per phase, {title}: " + ", ".join(f"phase {i}" for i in range(len(evaluated))))
        for index, name in enumerate(evaluated[0]["task_names"]):
            cells = " ".join(f"{result['success'][index]:.1f}" for result in evaluated)
            print(f"  {name:20s} {cells}")


if __name__ == "__main__":
    main(sys.argv[1:])
