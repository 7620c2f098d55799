"""The replay bench's speed: every scheduler over thousands of replicates, on one core.

Run: ``OMP_NUM_THREADS=1 .venv/bin/python benchmarks/bench_replay.py`` (``--help`` for the options).
43 synthetic tasks (the ``demo`` command's curves), 3 initial demos per task, 9 rounds of 129, 2 000
replicates per scheduler: the paper-regime study's shape. Prints each arm's seconds, its seconds per
replicate against ``need``'s (side by side, one run), and the total against the target.

Target: the whole comparison (every scheduler a success curve can drive, uniform and both oracles)
in under 60 s on one core.
"""

from __future__ import annotations

import argparse
import time

from lerobot_mtdagger.analysis.replay import ReplaySetting, default_arms, run_bench, synthetic_curves

TARGET_S = 60.0


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--tasks", type=int, default=43, help="synthetic tasks (default 43)")
    parser.add_argument("--rounds", type=int, default=9, help="DAgger rounds (default 9)")
    parser.add_argument(
        "--replicates", type=int, default=2000, help="replicates per scheduler (default 2000)"
    )
    args = parser.parse_args()
    setting = ReplaySetting(rounds=args.rounds, budget_per_round=3 * args.tasks, replicates=args.replicates)
    curves = synthetic_curves(args.tasks, 1.0, 30.0, setting)
    start = time.perf_counter()
    summaries = run_bench(curves, setting, default_arms())
    total = time.perf_counter() - start
    need = next(s.seconds for s in summaries if s.label == "need")
    print(f"{args.tasks} tasks, {args.rounds} rounds, {args.replicates} replicates per scheduler")
    for summary in summaries:
        print(f"  {summary.label:18s} {summary.seconds:6.1f} s   x{summary.seconds / need:5.2f} need's")
    verdict = "meets" if total <= TARGET_S else "misses"
    print(f"total {total:.1f} s against the {TARGET_S:.0f} s target ({total / TARGET_S:.2f}x): {verdict} it")


if __name__ == "__main__":
    main()
