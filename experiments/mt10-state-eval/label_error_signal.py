"""Would the expert-label error on the learner's own states be a better scheduling signal?

Offline, from the study's round datasets (no new rollout): on the steps the learner executed in DAgger
round k (collected by policy k-1), the per-task mean squared distance between the learner's action
(``executed_action``) and the expert's label (``action``). Pearson's r against the final per-task
evaluation success (phase 6, 20 episodes per task), to set beside the r of task need and gain in
``report/report.md`` (the same task-seeds). From the repository root, after run.sh:

    .venv/bin/python experiments/mt10-state-eval/label_error_signal.py
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pandas as pd
import pyarrow.parquet as pq
from scipy import stats

RUNS = Path("outputs/mt10-state-eval/runs")
RESULTS = Path("experiments/mt10-state-eval/report/results.json")
METHODS = ("uniform", "need", "need_raw", "gain")
FINAL_PHASE = 6
NUM_TASKS = 10


def label_error_per_task(run: Path, round_index: int) -> np.ndarray:
    """Mean squared learner-vs-expert action distance per task on the learner's steps (NaN: none)."""
    files = sorted((run / "rounds" / f"round-{round_index:03d}" / "data").glob("*/*.parquet"))
    table = pd.concat([pq.read_table(f).to_pandas() for f in files])
    learner = table["learner_acted"].map(lambda v: bool(np.asarray(v).reshape(-1)[0]))
    table = table[learner]
    errors = np.full(NUM_TASKS, np.nan)
    for task in range(NUM_TASKS):
        steps = table[table["task_index"] == task]
        if len(steps):
            label = np.stack(steps["action"].to_numpy())
            executed = np.stack(steps["executed_action"].to_numpy())
            errors[task] = float(np.mean(np.sum((label - executed) ** 2, axis=1)))
    return errors


def main() -> None:
    """Prints r(label error, final success) per method and round."""
    rows = json.loads(RESULTS.read_text())
    by_key = {(r["method"], r["seed"], r["round"]): r for r in rows if r["method"] in METHODS}
    seeds = sorted({seed for _, seed, _ in by_key})
    for method in METHODS:
        final = {seed: np.asarray(by_key[(method, seed, FINAL_PHASE)]["eval_success"]) for seed in seeds}
        line = [f"{method:9s}"]
        for round_index in (2, 4, 6):
            errors = [label_error_per_task(RUNS / f"{method}-seed{seed}", round_index) for seed in seeds]
            x, y = np.concatenate(errors), np.concatenate([final[seed] for seed in seeds])
            keep = ~np.isnan(x)
            line.append(f"label error, round {round_index}: r = {stats.pearsonr(x[keep], y[keep])[0]:+.2f}")
        print(" | ".join(line))


if __name__ == "__main__":
    main()
