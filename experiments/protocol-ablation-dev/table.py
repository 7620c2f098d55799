"""Prints the README's results table of the protocol ablation from each variant's results.csv.

Eval success after the last phase (12 expert demos per task) per method: the mean over seeds with each
seed's value and the expert-labelled frames per task, then need - uniform and need - BC, paired over
seeds with 95% t intervals. Reads ``<variant>/results.csv`` beside this file (copied there from
``outputs/ablation-dev/<variant>/`` when a variant is complete). From the repository root:

    .venv/bin/python experiments/protocol-ablation-dev/table.py
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

from lerobot_mtdagger.analysis.stats import paired_difference

HERE = Path(__file__).parent
VARIANTS = [
    "default",
    "mixing-step",
    "rollout-cap-200",
    "normalisation-recompute",
    "retrain-epochs",
    "sampling-balanced",
    "rollout-expert-2x",
    "beta-0",
    "beta-decay-0.25",
    "plateau",
]
METHODS = ["bc", "uniform", "need", "gain"]
DEMOS = 12.0


def final_success(rows: pd.DataFrame, method: str) -> pd.DataFrame:
    """Per seed: eval success and expert-labelled frames per task at DEMOS demos per task."""
    chosen = rows[(rows["method"] == method) & (rows["demos_per_task_mean"] == DEMOS)]
    return chosen.set_index("seed")[["eval_success_mean", "expert_frames_per_task_mean"]].sort_index()


def cell(final: pd.DataFrame) -> str:
    """``mean (seed / seed / seed; frames fr.)`` or ``-`` when the method did not run."""
    if final.empty:
        return "-"
    seeds = " / ".join(f"{value:.2f}" for value in final["eval_success_mean"])
    frames = final["expert_frames_per_task_mean"].mean()
    return f"{final['eval_success_mean'].mean():.3f} ({seeds}; {frames:.0f} fr.)"


def difference(first: pd.DataFrame, second: pd.DataFrame) -> str:
    """Paired difference of eval success over the seeds both ran, or ``-``."""
    seeds = first.index.intersection(second.index)
    if first.empty or second.empty or len(seeds) < 2:
        return "-"
    interval = paired_difference(
        first.loc[seeds, "eval_success_mean"].tolist(), second.loc[seeds, "eval_success_mean"].tolist()
    )
    return f"{interval.mean:+.3f} [{interval.low:+.3f}, {interval.high:+.3f}]"


def main() -> None:
    """Prints the table (Markdown) for every variant whose results.csv is here."""
    print("| variant | " + " | ".join(METHODS) + " | need - uniform | need - BC |")
    print("|---" * (len(METHODS) + 3) + "|")
    for variant in VARIANTS:
        path = HERE / variant / "results.csv"
        if not path.is_file():
            continue
        rows = pd.read_csv(path)
        finals = {method: final_success(rows, method) for method in METHODS}
        cells = [cell(finals[method]) for method in METHODS]
        need_uniform = difference(finals["need"], finals["uniform"])
        need_bc = difference(finals["need"], finals["bc"])
        print(f"| {variant} | " + " | ".join(cells) + f" | {need_uniform} | {need_bc} |")


if __name__ == "__main__":
    main()
