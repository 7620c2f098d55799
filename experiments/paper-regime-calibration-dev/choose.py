"""The calibration rule of ``run.sh`` (steps 2 and 3), applied to its outputs; prints what it decides.

``choose.py OUT --attempt K`` prints a table of every noise scale (kept tasks, their mean expert
success, how many lie in [0.80, 0.95]), the rule's decision, then ``scale: L`` and ``tasks: a,b,...``
for the K-th scale to check (0: the rule's choice; 1, 2: the next larger qualifying scales), or no
``scale:`` line when none is left. ``--bc OUT/bc-noise-L/results.json`` instead prints BC's success
at 6 and 18 demos per task per seed and exits 0 if the regime is accepted (BC below 0.80 at 18 demos in
mean over seeds), 1 if not.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

KEEP = 0.80  # the paper's rule: tasks whose expert succeeds at least this often are kept
BAND = (0.80, 0.95)  # the target expert success (each kept task, and their mean)
MIN_KEPT = 30
FALLBACK_TARGET = 0.875
BC_BUDGET, BC_THRESHOLD = 18.0, 0.80


def scale_summaries(sweep: dict) -> list[dict]:
    """Per noise scale: the kept tasks, their mean success, and how many lie in the band."""
    scales = sorted({float(level) for task in sweep["tasks"] for level in task["levels"]})
    summaries = []
    for scale in scales:
        success = {
            task["task"]: task["levels"][str(scale)]["success"]
            for task in sweep["tasks"]
            if not task["heldout"]
        }
        kept = [name for name, rate in success.items() if rate >= KEEP]
        kept_mean = sum(success[name] for name in kept) / len(kept) if kept else float("nan")
        in_band = sum(BAND[0] <= success[name] <= BAND[1] for name in kept)
        qualifies = len(kept) >= MIN_KEPT and BAND[0] <= kept_mean <= BAND[1]
        all_mean = sum(success.values()) / len(success)
        summaries.append(
            {
                "scale": scale,
                "kept": kept,
                "kept_mean": kept_mean,
                "in_band": in_band,
                "qualifies": qualifies,
                "mean": all_mean,
            }
        )
    return summaries


def order_to_check(summaries: list[dict]) -> tuple[list[dict], str]:
    """The scales to check in order (the rule's choice first, then larger ones), and what was decided."""
    qualifying = [s for s in summaries if s["qualifies"]]
    if qualifying:
        chosen = max(qualifying, key=lambda s: (s["in_band"], -s["scale"]))
        later = [s for s in qualifying if s["scale"] > chosen["scale"]]
        return [chosen, *later], f"rule: scale {chosen['scale']:g} qualifies with the most kept tasks in band"
    large_enough = [s for s in summaries if len(s["kept"]) >= MIN_KEPT]
    if not large_enough:
        return [], f"no scale keeps {MIN_KEPT} tasks: the rule cannot be met"
    chosen = min(large_enough, key=lambda s: (abs(s["kept_mean"] - FALLBACK_TARGET), s["scale"]))
    later = [s for s in large_enough if s["scale"] > chosen["scale"]]
    return [chosen, *later], (
        f"NO scale qualifies; fallback: scale {chosen['scale']:g}, kept mean nearest {FALLBACK_TARGET}"
    )


def bc_check(results: Path) -> bool:
    """Prints BC's success per budget and seed; True if BC stays below the threshold at its budget."""
    rows = [row for row in json.loads(results.read_text()) if row["method"] == "bc"]
    by_budget: dict[float, dict[int, float]] = {}
    for row in rows:
        by_budget.setdefault(row["demos_per_task_mean"], {})[row["seed"]] = row["eval_success_mean"]
    for budget, seeds in sorted(by_budget.items()):
        cells = ", ".join(f"seed {seed}: {value:.3f}" for seed, value in sorted(seeds.items()))
        print(f"BC at {budget:g} demos per task: {cells}; mean {sum(seeds.values()) / len(seeds):.3f}")
    at_budget = by_budget.get(BC_BUDGET)
    if not at_budget or len(at_budget) < 2:
        print(f"BC at {BC_BUDGET:g} demos per task has not finished on both seeds")
        return False
    mean = sum(at_budget.values()) / len(at_budget)
    accepted = mean < BC_THRESHOLD
    verdict = "accepted" if accepted else "not accepted"
    print(f"{verdict}: BC at {BC_BUDGET:g} demos per task {mean:.3f} vs threshold {BC_THRESHOLD}")
    return accepted


def main() -> int:
    """Prints the decision (or the BC check) for ``run.sh``; the exit code is the BC verdict."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("out", type=Path)
    parser.add_argument("--attempt", type=int, default=0)
    parser.add_argument("--bc", type=Path, default=None)
    args = parser.parse_args()
    if args.bc is not None:
        return 0 if bc_check(args.bc) else 1
    summaries = scale_summaries(json.loads((args.out / "expert-success.json").read_text()))
    print("| noise | mean success (all) | kept (>= 0.80) | kept mean | kept in [0.80, 0.95] | qualifies |")
    print("|---:|---:|---:|---:|---:|---|")
    for s in summaries:
        row = [f"{s['scale']:g}", f"{s['mean']:.3f}", str(len(s["kept"])), f"{s['kept_mean']:.3f}"]
        print("| " + " | ".join([*row, str(s["in_band"]), "yes" if s["qualifies"] else "no"]) + " |")
    order, decision = order_to_check(summaries)
    print(decision)
    if args.attempt < len(order):
        chosen = order[args.attempt]
        print(f"scale: {chosen['scale']:g}")
        print("tasks: " + ",".join(chosen["kept"]))
    return 0


if __name__ == "__main__":
    sys.exit(main())
