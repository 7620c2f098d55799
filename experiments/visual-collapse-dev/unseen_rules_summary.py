"""Unseen-drawer success of the kitchen runs' phase policies under the two rules of ``eval --unseen_rule``.

    .venv/bin/python experiments/visual-collapse-dev/unseen_rules_summary.py outputs/visual-dev/unseen-rules

Reads the ``eval`` JSONs that ``unseen-rules.sh`` writes (``kitchen-seed<S>-phase<k>-<rule>.json``: 4
unseen drawers x 20 episodes, evaluation seed 9000). Prints the mean success and progress per seed,
phase and rule, then the outcomes fixed before any evaluation:

- primary: ``nearest - shared`` in unseen success averaged over phases 0-2, paired over the seeds
  that have all six evaluations, mean and 95% t interval;
- secondary: ``nearest - shared`` per phase; under each rule the change from phase 0 to phases 1
  and 2 (the decline seen under ``shared``); per drawer, each rule's success per phase (mean over seeds).
"""

from __future__ import annotations

import json
import re
import sys
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.stats import mean_interval

NAME = re.compile(r"^kitchen-seed(?P<seed>\d+)-phase(?P<phase>\d)-(?P<rule>shared|nearest)\.json$")
PHASES = (0, 1, 2)
RULES = ("shared", "nearest")


def load(folder: Path) -> dict[tuple[int, int, str], dict]:
    """The evaluation results by (seed, phase, rule)."""
    results = {}
    for path in sorted(folder.glob("*.json")):
        match = NAME.match(path.name)
        if match:
            results[(int(match["seed"]), int(match["phase"]), match["rule"])] = json.loads(path.read_text())
    return results


def t_interval(values: list[float]) -> str:
    """Mean and 95% t interval over the values (``mean_interval``; the mean alone for one value)."""
    interval = mean_interval(values)
    if interval.n < 2:
        return f"{interval.mean:+.3f} (n=1)"
    per_seed = " / ".join(f"{v:+.3f}" for v in values)
    return f"{interval.mean:+.3f} [{interval.low:+.3f}, {interval.high:+.3f}] ({per_seed})"


def main(folder: Path) -> None:
    """Prints the tables and outcomes."""
    results = load(folder)
    seeds = sorted({seed for seed, _, _ in results})
    print("seed  phase  shared (progress)  nearest (progress)")
    for seed in seeds:
        for phase in PHASES:
            cells = []
            for rule in RULES:
                result = results.get((seed, phase, rule))
                cells.append(
                    "   -   " if result is None else f"{result['mean']:.3f} ({result['mean_progress']:.2f})"
                )
            print(f"{seed:<5} {phase:<6} {cells[0]:<18} {cells[1]}")
    complete = [s for s in seeds if all((s, p, r) in results for p in PHASES for r in RULES)]
    print(f"\nseeds with all six evaluations: {complete}")
    if not complete:
        return

    def success(seed: int, phase: int, rule: str) -> float:
        return results[(seed, phase, rule)]["mean"]

    primary = [
        float(np.mean([success(s, p, "nearest") - success(s, p, "shared") for p in PHASES])) for s in complete
    ]
    print(f"PRIMARY nearest - shared, mean over phases 0-2: {t_interval(primary)}")
    for phase in PHASES:
        diffs = [success(s, phase, "nearest") - success(s, phase, "shared") for s in complete]
        print(f"  phase {phase}: nearest - shared {t_interval(diffs)}")
    for rule in RULES:
        means = [float(np.mean([success(s, p, rule) for s in complete])) for p in PHASES]
        print(f"{rule}: mean success by phase " + " -> ".join(f"{m:.3f}" for m in means))
        for phase in PHASES[1:]:
            change = [success(s, phase, rule) - success(s, 0, rule) for s in complete]
            print(f"  phase {phase} - phase 0: {t_interval(change)}")
    tasks = results[(complete[0], 0, "shared")]["task_names"]
    print("\nper drawer, mean over seeds, phases 0 / 1 / 2:")
    for index, task in enumerate(tasks):
        cells = []
        for rule in RULES:
            values = [np.mean([results[(s, p, rule)]["success"][index] for s in complete]) for p in PHASES]
            cells.append(f"{rule} " + " / ".join(f"{v:.2f}" for v in values))
        acted = results[(complete[0], 0, "nearest")].get("acted_as", {}).get(task, "?")
        print(f"  {task:<20} {cells[0]}   {cells[1]}   (nearest acts as {acted})")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
