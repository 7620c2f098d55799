"""``compare`` with and without a shared round 0, side by side: wall time, and the same results.

Run: ``.venv/bin/python benchmarks/bench_share_round0.py`` (preset ``small``, MT10 state: uniform, need
and gain on seed 0, one run at a time, one thread) or with other ``compare``/run options, e.g.
``--dagger.rounds=1``; ``--repeats=N`` (first) runs the pair N times, interleaved, and takes medians.
The compares go to temporary folders, the unshared one first in each pair.

Printed: each compare's wall time and their ratio; the ratio expected from the unshared compare's wall
time less the phase 0 of every run but the first (from the runs' own timings); whether every evaluated
round of every run has the same success in both (it must: the copied round 0 is the same to the bit).
Target: the same results, and a ratio within 0.05 of the expected one.
"""

from __future__ import annotations

import json
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

METHODS = "[uniform,need,gain]"
SLACK = 0.05


def run_compare(folder: Path, extra: list[str], share: bool) -> float:
    """Wall time (s) of one ``compare`` into ``folder``."""
    command = [
        sys.executable,
        "-m",
        "lerobot_mtdagger.cli",
        "compare",
        f"--methods={METHODS}",
        "--seeds=[0]",
        "--jobs=1",
        f"--output_dir={folder}",
        f"--share_round0={str(share).lower()}",
        *extra,
    ]
    start = time.perf_counter()
    subprocess.run(command, check=True, env={**os.environ, "OMP_NUM_THREADS": "1"}, stdout=subprocess.DEVNULL)
    return time.perf_counter() - start


def phase_seconds(run: Path) -> list[float]:
    """The seconds each phase of a run timed itself (collect, write, load, train, eval), by phase."""
    totals = []
    for training in sorted(run.glob("policies/round-*/training.json")):
        timings = json.loads(training.read_text())["timings"]
        totals.append(sum(value for value in timings.values() if isinstance(value, int | float)))
    return totals


def expected_ratio(runs: Path, own_s: float) -> float:
    """Shared over unshared wall time if every run but the first skips its phase 0 (their timings)."""
    phases = [phase_seconds(run) for run in sorted(runs.iterdir()) if run.is_dir()]
    saved = sum(p[0] for p in phases[1:])
    return (own_s - saved) / own_s


def successes(folder: Path) -> list[tuple]:
    """(method, round, success per task) of every evaluated round, in order."""
    rows = json.loads((folder / "results.json").read_text())
    return sorted((row["method"], row["round"], tuple(row["eval_success"])) for row in rows)


def main() -> int:
    extra = sys.argv[1:]
    repeats = 1
    if extra and extra[0].startswith("--repeats="):
        repeats, extra = int(extra[0].split("=", 1)[1]), extra[1:]
    own_times, shared_times, expected_ratios, same = [], [], [], True
    for _ in range(repeats):
        with tempfile.TemporaryDirectory() as tmp:
            own, shared = Path(tmp) / "own", Path(tmp) / "shared"
            own_times.append(run_compare(own, extra, share=False))
            shared_times.append(run_compare(shared, extra, share=True))
            expected_ratios.append(expected_ratio(own / "runs", own_times[-1]))
            same = same and successes(own) == successes(shared)
    own_s, shared_s, expected = (statistics.median(v) for v in (own_times, shared_times, expected_ratios))
    ratio = shared_s / own_s
    print(f"compare {METHODS} seed 0, --jobs=1, 1 thread {' '.join(extra)}; median of {repeats}")
    print(f"every run makes its own round 0 : {own_s:7.1f} s  {[round(t, 1) for t in own_times]}")
    print(f"round 0 shared                  : {shared_s:7.1f} s  {[round(t, 1) for t in shared_times]}")
    print(f"ratio shared / own = {ratio:.3f} (expected from the runs' phase timings: {expected:.3f})")
    print(f"every evaluated round the same in both: {same}")
    passed = same and ratio <= expected + SLACK
    print("PASS" if passed else "FAIL")
    return 0 if passed else 1


if __name__ == "__main__":
    sys.exit(main())
