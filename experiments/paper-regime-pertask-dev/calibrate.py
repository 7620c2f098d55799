"""The rules of ``run.sh``, applied: each task's noise scale, the kept tasks, the BC check.

Steps 1, 2 and 3 of ``run.sh``; written with it on 2026-11-28, before any of its runs.

- ``calibrate.py noise OUT SWEEP.json``: per MT50 task, the scale from the committed sweep (and at most two
  bisections, measured here) whose expert success is nearest 0.875 inside [0.80, 0.95]; writes
  ``OUT/noise-by-task.json`` and prints a table with where each scale came from.
- ``calibrate.py kept OUT``: from the fresh check ``OUT/check.json`` (``benchmarks/expert_success.py`` with
  that map, other reset seeds), prints the summary, then ``tasks: a,b,...`` (success >= 0.80, the paper's
  rule) and ``map: {a: 0.1, ...}`` (their scales, the ``--expert.noise_by_task`` value).
- ``calibrate.py bc OUT``: BC's success at 6 and 18 demos per task per seed (``OUT/bc/results.json``);
  exits 0 if the regime is accepted (mean over the seeds at 18 demos below 0.80), 1 if not.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

BAND = (0.80, 0.95)
TARGET = 0.875
KEEP = 0.80
BISECTIONS = 2
EPISODES, FIRST_SEED, NOISE_SEED, CORRELATION = 20, 1000, 100, 0.9  # the sweep's
BC_BUDGET, BC_THRESHOLD = 18.0, 0.80


def in_band(success: float) -> bool:
    """Whether an expert's success lies in the paper's 0.80-0.95."""
    return BAND[0] <= success <= BAND[1]


def measure(task: str, scale: float) -> float:
    """The task's expert success at ``scale`` on the sweep's episodes (reset seeds, noise keys, seed)."""
    from lerobot_mtdagger.envs import make_suite
    from lerobot_mtdagger.experts import ExpertNoise, make_expert, run_expert_episode

    suite = make_suite("metaworld-mt50")
    index = suite.task_names.index(task)
    env, expert = suite.make_env(task), make_expert(suite, task)
    noise = ExpertNoise(scale=scale, correlation=CORRELATION, seed=NOISE_SEED)
    low, high = env.action_space.low, env.action_space.high
    wins = [
        run_expert_episode(
            env, expert, FIRST_SEED + e, noise=noise.episode_process((0, index, e), low, high)
        ).success
        for e in range(EPISODES)
    ]
    env.close()
    return float(np.mean(wins))


def choose_scale(levels: dict[float, float], measure_at) -> tuple[float, float, str]:
    """The rule for one task: ``(scale, its success, where it came from)``.

    ``levels`` maps the sweep's scales to the task's success. In band: the one nearest 0.875 (ties: the
    larger scale). Above the band at every scale: the largest. Else bisect between the largest scale
    above the band below the first one under 0.80, and that one, at most twice; if no midpoint lands in
    the band, the largest measured scale at or above 0.80 (never one under it).
    """
    measured = dict(levels)
    band = [scale for scale, rate in measured.items() if in_band(rate)]
    if band:
        best = min(band, key=lambda s: (abs(measured[s] - TARGET), -s))
        return best, measured[best], "sweep"
    if all(rate > BAND[1] for rate in measured.values()):
        top = max(measured)
        return top, measured[top], "above the band at every scale: the largest"
    low_scale = min(s for s, rate in measured.items() if rate < BAND[0])
    above = [s for s, rate in measured.items() if rate > BAND[1] and s < low_scale]
    if not above:
        return 0.0, measured.get(0.0, float("nan")), "under 0.80 without noise"
    high_ok, low_bad = max(above), low_scale
    for _ in range(BISECTIONS):
        middle = round((high_ok + low_bad) / 2, 4)
        measured[middle] = measure_at(middle)
        if in_band(measured[middle]):
            return middle, measured[middle], "bisected"
        if measured[middle] > BAND[1]:
            high_ok = middle
        else:
            low_bad = middle
    best = max(s for s, rate in measured.items() if rate >= KEEP)
    return best, measured[best], "bisected, none in band: the largest scale at or above 0.80"


def noise_step(out: Path, sweep_path: Path) -> None:
    """Step 1: writes ``noise-by-task.json`` (and ``noise-by-task.md``) into ``out``."""
    sweep = json.loads(sweep_path.read_text())
    chosen, lines = {}, ["| task | scale | success | from |", "|---|---:|---:|---|"]
    for row in sweep["tasks"]:
        if row["heldout"]:
            continue
        levels = {float(level): value["success"] for level, value in row["levels"].items()}
        scale, success, source = choose_scale(levels, lambda s, task=row["task"]: measure(task, s))
        chosen[row["task"]] = scale
        lines.append(f"| {row['task']} | {scale} | {success:.2f} | {source} |")
        print(lines[-1], flush=True)
    (out / "noise-by-task.md").write_text("\n".join(lines) + "\n")
    (out / "noise-by-task.json").write_text(json.dumps(chosen, indent=1))


def kept_step(out: Path) -> None:
    """Step 2: the fresh check's summary, the kept tasks and their map."""
    scales = json.loads((out / "noise-by-task.json").read_text())
    check = {
        row["task"]: row["levels"]["0.0"]["success"]
        for row in json.loads((out / "check.json").read_text())["tasks"]
    }
    kept = [task for task, rate in check.items() if rate >= KEEP]
    rates = [check[task] for task in kept]
    print(
        f"fresh check: mean over 50 tasks {np.mean(list(check.values())):.3f}; kept (>= {KEEP}) {len(kept)}, "
        f"their mean {np.mean(rates):.3f}, in [0.80, 0.95] {sum(in_band(r) for r in rates)}, "
        f"above 0.95 {sum(r > BAND[1] for r in rates)}"
    )
    print("dropped: " + ", ".join(f"{task} {rate:.2f}" for task, rate in check.items() if rate < KEEP))
    print("tasks: " + ",".join(kept))
    print("map: {" + ", ".join(f"{task}: {scales[task]}" for task in kept) + "}")


def bc_step(out: Path) -> int:
    """Step 3: BC at 6 and 18 demos per task per seed; 0 if the regime is accepted."""
    rows = json.loads((out / "bc" / "results.json").read_text())
    rows = rows["rows"] if isinstance(rows, dict) else rows
    by_budget: dict[float, dict[int, float]] = {}
    for row in rows:
        by_budget.setdefault(float(row["demos_per_task_mean"]), {})[int(row["seed"])] = row[
            "eval_success_mean"
        ]
    for budget, seeds in sorted(by_budget.items()):
        cells = ", ".join(f"seed {seed} {rate:.3f}" for seed, rate in sorted(seeds.items()))
        print(f"BC {budget:.0f} demos/task: {cells}; mean {np.mean(list(seeds.values())):.3f}")
    mean = float(np.mean(list(by_budget[BC_BUDGET].values())))
    accepted = mean < BC_THRESHOLD
    verdict = "accepted" if accepted else "not accepted"
    print(f"{verdict}: BC at {BC_BUDGET:.0f} demos per task {mean:.3f} (the regime needs < {BC_THRESHOLD})")
    return 0 if accepted else 1


def main() -> int:
    """Dispatches ``noise``, ``kept`` or ``bc``."""
    step, out = sys.argv[1], Path(sys.argv[2])
    if step == "noise":
        noise_step(out, Path(sys.argv[3]))
    elif step == "kept":
        kept_step(out)
    elif step == "bc":
        return bc_step(out)
    else:
        raise SystemExit(f"unknown step {step!r}: noise, kept or bc")
    return 0


if __name__ == "__main__":
    sys.exit(main())
