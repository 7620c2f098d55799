"""One ``lerobot-mtdagger run`` end to end: wall time, its phase breakdown and peak memory.

Run: ``.venv/bin/python benchmarks/bench_run.py`` (the README's main command: preset ``small``, MT10
state) or, for example, ``.venv/bin/python benchmarks/bench_run.py --preset=metaworld-state
--dagger.rounds=3`` (MT50). Every argument is passed to ``lerobot-mtdagger run``; the output goes to a
temporary folder unless ``--output_dir`` is given.

Printed:

- wall time of the command (after the install: the imports and the env workers' start are in it);
- per round, the phases the run timed itself (collect, write, load, train, eval); ``start-up and
  the rest`` is the wall time minus their sum;
- the load time per phase against the round index (it stays flat when only the new round is read);
- peak memory of the run's process tree (the main process and its env workers): the largest sum of
  RSS (sampled every 0.1 s; pages the forked workers share with the main process count once per
  process), the largest sum of PSS (shared pages split between their sharers; sampled every 2 s,
  reading it costs ~20 ms per process) and the largest RSS of a single process.

Targets on the 2-core machine, alone: the default command at most 60 s of wall time; a whole
``--preset=drawers-pointcloud`` run (11 drawers, 10 DAgger rounds) at most 60 min and a whole
``--preset=metaworld-pixels`` run (MT10 RGB, 5 DAgger rounds) at most 90 min (a verdict is printed
when the arguments are only the preset and ``--output_dir``).
"""

from __future__ import annotations

import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from lerobot_mtdagger.analysis.results import PHASE_TIMINGS as PHASES

TARGET_S = 60.0
PRESET_TARGETS_S = {"drawers-pointcloud": 3600.0, "metaworld-pixels": 5400.0}
"""Wall-time targets of whole preset runs (seconds), keyed by preset."""


def _children(pid: int) -> list[int]:
    """Direct children of ``pid`` (Linux /proc)."""
    path = Path(f"/proc/{pid}/task/{pid}/children")
    try:
        return [int(child) for child in path.read_text().split()]
    except OSError:
        return []


def _tree(pid: int) -> list[int]:
    """``pid`` and all its descendants."""
    pids, frontier = [pid], [pid]
    while frontier:
        frontier = [child for parent in frontier for child in _children(parent)]
        pids += frontier
    return pids


def _memory_kb(pid: int, field: str) -> int:
    """A field of /proc/<pid>/smaps_rollup (``Pss``, ``Rss``) in kB; 0 when the process is gone."""
    try:
        for line in Path(f"/proc/{pid}/smaps_rollup").read_text().splitlines():
            if line.startswith(field + ":"):
                return int(line.split()[1])
    except (OSError, ValueError):
        return 0
    return 0


def _rss_kb(pid: int) -> int:
    """Resident set size of ``pid`` from /proc/<pid>/statm (cheap); 0 when the process is gone."""
    try:
        return int(Path(f"/proc/{pid}/statm").read_text().split()[1]) * os.sysconf("SC_PAGE_SIZE") // 1024
    except (OSError, ValueError, IndexError):
        return 0


class MemorySampler(threading.Thread):
    """Samples the memory of a process tree until stopped; keeps the peaks.

    RSS (cheap to read) every 0.1 s; PSS every ``PSS_EVERY`` samples, because reading
    ``smaps_rollup`` of a 1 GB process costs about 20 ms and would slow the run it measures.
    """

    PSS_EVERY = 20

    def __init__(self, pid: int) -> None:
        super().__init__(daemon=True)
        self.pid = pid
        self.peak_pss_kb = 0
        self.peak_rss_sum_kb = 0
        self.peak_rss_kb = 0
        self.peak_processes = 0
        self.stop = threading.Event()

    def run(self) -> None:
        sample = 0
        while not self.stop.is_set():
            pids = _tree(self.pid)
            rss = [_rss_kb(p) for p in pids]
            self.peak_rss_sum_kb = max(self.peak_rss_sum_kb, sum(rss))
            self.peak_rss_kb = max([self.peak_rss_kb, *rss])
            self.peak_processes = max(self.peak_processes, len(pids))
            if sample % self.PSS_EVERY == 0:
                self.peak_pss_kb = max(self.peak_pss_kb, sum(_memory_kb(p, "Pss") for p in pids))
            sample += 1
            self.stop.wait(0.1)


def main() -> None:
    args = sys.argv[1:]
    target = target_of(args)
    if any(a in ("-h", "--help") for a in args):
        print(__doc__)
        return
    with tempfile.TemporaryDirectory(prefix="bench-run-") as scratch:
        if not any(a.startswith("--output_dir") for a in args):
            args.append(f"--output_dir={Path(scratch) / 'run'}")
        output = Path(next(a.split("=", 1)[1] for a in args if a.startswith("--output_dir")))
        command = [str(Path(sys.executable).parent / "lerobot-mtdagger"), "run", "--progress=false", *args]
        env = {**os.environ, "MUJOCO_GL": os.environ.get("MUJOCO_GL", "egl")}
        start = time.perf_counter()
        process = subprocess.Popen(command, env=env, stdout=subprocess.PIPE, text=True)
        sampler = MemorySampler(process.pid)
        sampler.start()
        stdout, _ = process.communicate()
        wall = time.perf_counter() - start
        sampler.stop.set()
        sampler.join()
        if process.returncode != 0:
            raise SystemExit(f"the run failed with exit status {process.returncode}")
        report(command, stdout, wall, output, sampler, target)


def target_of(args: list[str]) -> tuple[str, float] | None:
    """The command's wall-time target: the default command's or a bare preset's (None: no target)."""
    others = [a for a in args if not a.startswith("--output_dir")]
    if not others:
        return "the default command", TARGET_S
    preset = others[0].removeprefix("--preset=")
    if len(others) == 1 and preset in PRESET_TARGETS_S:
        return f"--preset={preset}", PRESET_TARGETS_S[preset]
    return None


def report(
    command: list[str],
    stdout: str,
    wall: float,
    output: Path,
    sampler: MemorySampler,
    target: tuple[str, float] | None,
) -> None:
    """Prints the tables (and the verdict against the target for the default command)."""
    print("$ " + " ".join(command[1:]))
    print(stdout.rstrip())
    rounds = sorted((output / "policies").glob("round-*"))
    timings = [json.loads((r / "training.json").read_text())["timings"] for r in rounds]
    print(f"\nwall time {wall:.1f} s; phases per round (s):")
    print("| round | " + " | ".join(p.removesuffix("_s") for p in PHASES) + " | total |")
    print("|------:|" + "------:|" * (len(PHASES) + 1))
    totals = dict.fromkeys(PHASES, 0.0)
    for index, timing in enumerate(timings):
        values = [timing.get(p, 0.0) for p in PHASES]
        for phase, value in zip(PHASES, values, strict=True):
            totals[phase] += value
        print(f"| {index} | " + " | ".join(f"{v:.1f}" for v in values) + f" | {sum(values):.1f} |")
    print("| all | " + " | ".join(f"{totals[p]:.1f}" for p in PHASES) + f" | {sum(totals.values()):.1f} |")
    print(f"start-up and the rest (imports, workers, summaries): {wall - sum(totals.values()):.1f} s")
    loads = [t.get("load_s", 0.0) for t in timings]
    if len(loads) > 2:
        # From round 1 on the load phase also reads the previous policy (warm start).
        print(
            f"load per phase against the round index: {[round(x, 3) for x in loads]} s "
            f"(last / round 1 = {loads[-1] / max(loads[1], 1e-9):.2f})"
        )
    print(
        f"peak memory over {sampler.peak_processes} processes: "
        f"RSS summed {sampler.peak_rss_sum_kb / 1024:.0f} "
        f"MiB (counts shared pages once per process), PSS summed {sampler.peak_pss_kb / 1024:.0f} MiB "
        f"(sampled every 2 s); largest single-process RSS {sampler.peak_rss_kb / 1024:.0f} MiB"
    )
    if target is not None:
        name, limit = target
        verdict = "PASS" if wall <= limit else "FAIL"
        print(f"{verdict}: wall time {wall:.1f} s (target for {name} <= {limit:.0f} s)")


if __name__ == "__main__":
    main()
