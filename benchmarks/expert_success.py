"""Measures each task's expert at given noise levels: success rate and episode length over seeded episodes.

Run: ``.venv/bin/python benchmarks/expert_success.py --suite metaworld-mt10 --episodes 20``. Prints a
markdown table, one row per task and one column pair per noise level: success over the reset seeds
``--first-seed``.., and mean steps to the first success. ``--noise 0 0.1 0.3`` measures the expert
with ``--expert.noise`` at each level (``--correlation``: ``--expert.noise_correlation``; the noise of
episode ``e`` of task ``i`` is the one a run draws for round 0, task ``i``, episode ``e`` with
``--noise-seed``). ``--noise-by-task MAP.json`` (``{task: scale}``, as ``--expert.noise_by_task``) gives
the named tasks their own scale at every level (a task's row then measures its own scale; the level
is the scale of the others). ``--jobs N`` measures N tasks at once (one process each); ``--json PATH``
also writes every number. ``--suite drawers`` also measures the held-out drawers (rows marked "held out").

Example (the paper-regime calibration, ``experiments/``): ``--suite metaworld-mt50 --noise 0 0.2 0.4
0.6 --correlation 0.9 --episodes 20 --jobs 2 --json outputs/expert-success-mt50.json``.
"""

from __future__ import annotations

import argparse
import json
import multiprocessing
from pathlib import Path

import numpy as np

from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.experts import ExpertNoise, make_expert, run_expert_episode


def measure_task(args: tuple[argparse.Namespace, str, int]) -> dict:
    """Success and steps of one task's expert at every noise level (its own env and expert)."""
    options, task_name, task_index = args
    suite = make_suite(options.suite, placement=options.placement)
    env, expert = suite.make_env(task_name), make_expert(suite, task_name)
    low, high = env.action_space.low, env.action_space.high
    seeds = range(options.first_seed, options.first_seed + options.episodes)
    result: dict = {"task": task_name, "heldout": task_name in suite.heldout_task_names, "levels": {}}
    result["own_scale"] = options.task_scales.get(task_name)
    own = tuple(sorted(options.task_scales.items()))
    for scale in options.noise:
        noise = ExpertNoise(
            scale=scale, correlation=options.correlation, seed=options.noise_seed, task_scales=own
        )
        episodes = [
            run_expert_episode(
                env, expert, seed, noise=noise.episode_process((0, task_index, e), low, high, task=task_name)
            )
            for e, seed in enumerate(seeds)
        ]
        lengths = [episode.steps for episode in episodes if episode.success]
        result["levels"][str(scale)] = {
            "success": float(np.mean([episode.success for episode in episodes])),
            "mean_steps": float(np.mean(lengths)) if lengths else None,
        }
    env.close()
    return result


def main() -> None:
    parser = argparse.ArgumentParser(
        description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter
    )
    parser.add_argument("--suite", default="metaworld-mt10")
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=1000)
    parser.add_argument("--placement", default=None, help="drawers only: kitchen (default) or narrow")
    parser.add_argument("--noise", type=float, nargs="+", default=[0.0], help="noise scales to measure")
    parser.add_argument("--correlation", type=float, default=0.0, help="step-to-step noise correlation")
    parser.add_argument("--noise-seed", type=int, default=0)
    parser.add_argument("--jobs", type=int, default=1, help="tasks measured at once (processes)")
    parser.add_argument("--json", type=Path, default=None, help="also write every number here")
    parser.add_argument(
        "--noise-by-task", type=Path, default=None, help="JSON {task: scale}: these tasks' own noise scale"
    )
    options = parser.parse_args()
    suite = make_suite(options.suite, placement=options.placement)
    tasks = suite.task_names + suite.heldout_task_names
    options.task_scales = json.loads(options.noise_by_task.read_text()) if options.noise_by_task else {}
    unknown = sorted(set(options.task_scales) - set(tasks))
    if unknown:
        parser.error(f"--noise-by-task names {', '.join(unknown)}, not a task of {options.suite}")
    work = [(options, task, index) for index, task in enumerate(tasks)]
    if options.jobs > 1:
        with multiprocessing.get_context("fork").Pool(options.jobs) as pool:
            results = pool.map(measure_task, work, chunksize=1)
    else:
        results = [measure_task(item) for item in work]
    levels = [str(scale) for scale in options.noise]
    print("| task | " + " | ".join(f"success @{s} | steps @{s}" for s in levels) + " |")
    print("|---|" + "---:|---:|" * len(levels))
    for row in results:
        label = f"{row['task']} (held out)" if row["heldout"] else row["task"]
        label += f" (own noise {row['own_scale']})" if row["own_scale"] is not None else ""
        cells = []
        for level in levels:
            measured = row["levels"][level]
            steps = measured["mean_steps"]
            cells += [f"{measured['success']:.2f}", f"{steps:.0f}" if steps is not None else "-"]
        print(f"| {label} | " + " | ".join(cells) + " |")
    means = [np.mean([row["levels"][level]["success"] for row in results]) for level in levels]
    print("| **mean** | " + " | ".join(f"**{mean:.3f}** |" for mean in means) + " |")
    if options.json is not None:
        options.json.parent.mkdir(parents=True, exist_ok=True)
        payload = {"options": {k: str(v) for k, v in vars(options).items()}, "tasks": results}
        options.json.write_text(json.dumps(payload, indent=1))


if __name__ == "__main__":
    main()
