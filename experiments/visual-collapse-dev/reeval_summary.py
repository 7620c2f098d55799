"""Mean success of every re-evaluated pixel or drawer policy, and the phases' paired changes over seeds.

    .venv/bin/python experiments/visual-collapse-dev/reeval_summary.py outputs/visual-dev/reeval

Reads the ``eval`` JSONs that ``reeval-pixels.sh`` and ``reeval-kitchen.sh`` write
(``<run>-seed<S>-round-00<k>.json``, 20 episodes per task, evaluation seed 9000 for every policy).
Prints per run and phase the mean success with its binomial standard error over its episodes, then
per run name the mean success of each phase over the seeds that have every phase, the change from
phase 0 to each later phase, per seed and as a mean with its 95% t interval over the seeds that have
both, and the per-task success of each phase averaged over seeds.
"""

from __future__ import annotations

import json
import re
import sys
from collections import defaultdict
from pathlib import Path

import numpy as np

from lerobot_mtdagger.analysis.stats import mean_interval

NAME = re.compile(r"^(?P<run>.+)-seed(?P<seed>\d+)-round-(?P<round>\d+)\.json$")


def load(folder: Path) -> dict[tuple[str, int, int], dict]:
    """The evaluation results by (run name, seed, phase)."""
    results = {}
    for path in sorted(folder.glob("*.json")):
        match = NAME.match(path.name)
        if match:
            key = (match["run"], int(match["seed"]), int(match["round"]))
            results[key] = json.loads(path.read_text())
    return results


def t_interval(values: list[float]) -> str:
    """Mean and 95% t interval (``mean_interval``; the mean alone for one value)."""
    interval = mean_interval(values)
    if interval.n < 2:
        return f"{interval.mean:+.3f} (1 seed)"
    return f"{interval.mean:+.3f} [{interval.low:+.3f}, {interval.high:+.3f}] ({interval.n} seeds)"


def phase_means(results: dict[tuple[str, int, int], dict], run: str) -> str:
    """The run's mean success per phase over the seeds that have every phase (what the rules read)."""
    phases = sorted({p for (name, _, p) in results if name == run})
    seeds = sorted({s for (name, s, _) in results if name == run})
    complete = [s for s in seeds if all((run, s, p) in results for p in phases)]
    if not complete:
        return "no seed has every phase"
    means = [np.mean([results[(run, s, p)]["mean"] for s in complete]) for p in phases]
    return " -> ".join(f"{m:.3f}" for m in means) + f" (phases {phases[0]}-{phases[-1]}, seeds {complete})"


def main(folder: Path) -> None:
    """Prints the three tables."""
    results = load(folder)
    print("| run | seed | phase | mean success | s.e. | episodes |")
    print("|---|---:|---:|---:|---:|---:|")
    for (run, seed, phase), result in sorted(results.items()):
        episodes = int(np.sum(result["episodes"]))
        mean = float(np.average(result["success"], weights=result["episodes"]))
        error = np.sqrt(mean * (1 - mean) / episodes)
        print(f"| {run} | {seed} | {phase} | {mean:.3f} | {error:.3f} | {episodes} |")
    for run in sorted({key[0] for key in results}):
        print(f"\n{run}: mean success by phase {phase_means(results, run)}")
        print(f"{run}: change of mean success from phase 0")
        for phase in (1, 2):
            changes = {
                seed: results[(run, seed, phase)]["mean"] - results[(run, seed, 0)]["mean"]
                for (name, seed, p) in results
                if name == run and p == phase and (run, seed, 0) in results
            }
            per_seed = ", ".join(f"{seed}: {change:+.3f}" for seed, change in sorted(changes.items()))
            if changes:
                print(f"  phase {phase}: {t_interval(list(changes.values()))}; per seed {per_seed}")
        by_task: dict[int, dict[str, list[float]]] = defaultdict(lambda: defaultdict(list))
        for (name, _, phase), result in results.items():
            if name == run:
                for task, success in zip(result["task_names"], result["success"], strict=True):
                    by_task[phase][task].append(success)
        tasks = sorted({task for phase in by_task.values() for task in phase})
        print("  | task | " + " | ".join(f"phase {p}" for p in sorted(by_task)) + " |")
        for task in tasks:
            cells = " | ".join(f"{np.mean(by_task[p][task]):.2f}" for p in sorted(by_task))
            print(f"  | {task} | {cells} |")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
