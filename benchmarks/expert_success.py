"""Measures each task's expert: success rate and episode length over seeded episodes.

Run: ``.venv/bin/python benchmarks/expert_success.py --suite metaworld-mt10 --episodes 20``. Prints a
markdown table (success over seeds 1000.., mean steps to the first success). ``--suite drawers``
also measures the held-out drawers (rows marked "held out").
"""

from __future__ import annotations

import argparse

import numpy as np

from lerobot_mtdagger.envs import make_suite
from lerobot_mtdagger.experts import make_expert, run_expert_episode


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--suite", default="metaworld-mt10")
    parser.add_argument("--episodes", type=int, default=20)
    parser.add_argument("--first-seed", type=int, default=1000)
    parser.add_argument("--placement", default=None, help="drawers only: kitchen (default) or narrow")
    args = parser.parse_args()
    suite = make_suite(args.suite, placement=args.placement)
    seeds = range(args.first_seed, args.first_seed + args.episodes)
    heldout = suite.heldout_task_names
    print("| task | success | mean steps (successful) |\n|---|---:|---:|")
    rates = []
    for task_name in suite.task_names + heldout:
        env = suite.make_env(task_name)
        expert = make_expert(suite, task_name)
        episodes = [run_expert_episode(env, expert, seed) for seed in seeds]
        env.close()
        rate = np.mean([e.success for e in episodes])
        lengths = [e.steps for e in episodes if e.success]
        rates.append(rate)
        label = f"{task_name} (held out)" if task_name in heldout else task_name
        print(f"| {label} | {rate:.2f} | {np.mean(lengths) if lengths else float('nan'):.0f} |")
    print(f"| **mean** | **{np.mean(rates):.3f}** | |")


if __name__ == "__main__":
    main()
