"""The pixel BC samplings' success by budget and seed, and the decision rule of ``run.sh``, applied.

Usage: ``.venv/bin/python docs/results/pixels-bc-dev/table.py docs/results/pixels-bc-dev/records``
(the folder ``save_records.sh`` fills:
``<sampling>/bc-<budget>demos-seed<seed>/policies/round-000/training.json``).

The rule, as fixed in ``run.sh`` before any run: the evaluation study's BC takes the sampling with
the highest 3-seed mean success over the three budgets among those whose mean at 60 is not below
their mean at 10 by more than 0.01; if neither qualifies, the highest mean, said so. It is applied
only when every (sampling, budget, seed) run has finished.
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

BUDGETS = (10, 30, 60)
SEEDS = (100, 101, 102)
DROP_ALLOWED = 0.01
RUN_NAME = re.compile(r"bc-(\d+)demos-seed(\d+)")


def read_records(folder: Path) -> dict[str, dict[tuple[int, int], float]]:
    """Mean success by sampling, then (budget, seed)."""
    results: dict[str, dict[tuple[int, int], float]] = {}
    for path in sorted(folder.glob("*/*/policies/round-000/training.json")):
        run = path.parents[2]
        match = RUN_NAME.fullmatch(run.name)
        if match is None:
            continue
        budget, seed = int(match.group(1)), int(match.group(2))
        success = json.loads(path.read_text())["eval"]["mean"]
        results.setdefault(run.parent.name, {})[(budget, seed)] = float(success)
    return results


def table(results: dict[str, dict[tuple[int, int], float]]) -> list[str]:
    """One row per sampling and budget: success per seed and the mean over the seeds done."""
    lines = ["| sampling | demos/task | " + " | ".join(f"seed {s}" for s in SEEDS) + " | mean |"]
    lines.append("|---|---:|" + "---:|" * (len(SEEDS) + 1))
    for sampling, runs in sorted(results.items()):
        for budget in BUDGETS:
            values = [runs.get((budget, seed)) for seed in SEEDS]
            done = [v for v in values if v is not None]
            cells = " | ".join("-" if v is None else f"{v:.3f}" for v in values)
            mean = f"{np.mean(done):.3f}" if done else "-"
            lines.append(f"| {sampling} | {budget} | {cells} | {mean} |")
    return lines


def decision(results: dict[str, dict[tuple[int, int], float]]) -> list[str]:
    """The rule of ``run.sh`` applied, or why it cannot be yet."""
    complete = {
        sampling: runs
        for sampling, runs in results.items()
        if all((b, s) in runs for b in BUDGETS for s in SEEDS)
    }
    if set(complete) != {"uniform", "balanced"}:
        return ["Decision: not yet (every sampling needs all 9 runs)."]
    lines, qualified, means = [], [], {}
    for sampling, runs in sorted(complete.items()):
        by_budget = {b: float(np.mean([runs[(b, s)] for s in SEEDS])) for b in BUDGETS}
        means[sampling] = float(np.mean(list(by_budget.values())))
        drop = by_budget[10] - by_budget[60]
        ok = drop <= DROP_ALLOWED
        qualified += [sampling] if ok else []
        lines.append(
            f"{sampling}: mean over budgets {means[sampling]:.3f}; 60 - 10 demos "
            f"{by_budget[60] - by_budget[10]:+.3f} ({'qualifies' if ok else 'drops: does not qualify'})"
        )
    pool = qualified or list(means)
    chosen = max(pool, key=lambda sampling: means[sampling])
    note = "" if qualified else " (neither qualified: the highest mean; BC's training needs more study)"
    lines.append(f"Decision: BC samples {chosen}{note}.")
    return lines


def main() -> None:
    """Prints the table and the decision for the records folder given as the only argument."""
    results = read_records(Path(sys.argv[1]))
    print("\n".join([*table(results), "", *decision(results)]))


if __name__ == "__main__":
    main()
