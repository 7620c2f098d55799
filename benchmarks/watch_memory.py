"""Peak memory of every ``lerobot-mtdagger run`` on this machine while a study runs, and the machine's.

Every ``--every`` seconds: for each process whose command line is a ``lerobot_mtdagger.cli run``, the
PSS summed over it and its env workers (shared pages split between their sharers), keyed by the
run's ``--output_dir``; and the machine's lowest ``MemAvailable``. The peaks are written to
``--output`` (JSON) after every sample, so the file holds them however the watch ends.

A study's own runs are measured where they run, with their neighbours: for example two pixel runs at
``--jobs=2`` on 24 GB. Usage::

    nohup .venv/bin/python benchmarks/watch_memory.py --output outputs/study-memory.json --match outputs/ &
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_run import _memory_kb, _tree  # noqa: E402

MARKER = "lerobot_mtdagger.cli\x00run\x00"


def run_processes() -> dict[str, int]:
    """``--output_dir`` -> pid of each running ``lerobot-mtdagger run`` process."""
    runs = {}
    for proc in Path("/proc").iterdir():
        if not proc.name.isdigit():
            continue
        try:
            cmdline = (proc / "cmdline").read_bytes().decode(errors="replace")
        except OSError:
            continue
        if MARKER not in cmdline:
            continue
        output = next(
            (a.split("=", 1)[1] for a in cmdline.split("\x00") if a.startswith("--output_dir=")), proc.name
        )
        runs[output] = int(proc.name)
    return runs


def available_mib() -> int:
    """The machine's MemAvailable (MiB)."""
    for line in Path("/proc/meminfo").read_text().splitlines():
        if line.startswith("MemAvailable:"):
            return int(line.split()[1]) // 1024
    raise RuntimeError("MemAvailable not found in /proc/meminfo")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--output", type=Path, required=True)
    parser.add_argument("--every", type=float, default=5.0, help="Seconds between samples.")
    parser.add_argument("--match", default="", help="Watch only runs whose --output_dir contains this.")
    args = parser.parse_args()
    peaks: dict[str, int] = {}
    lowest = None
    if args.output.exists():  # a watch started again goes on from the peaks it wrote
        stored = json.loads(args.output.read_text())
        peaks, lowest = stored.get("peak_pss_mib", {}), stored.get("lowest_available_mib")
        peaks = {output: pss for output, pss in peaks.items() if args.match in output}
    while True:
        watched = {output: pid for output, pid in run_processes().items() if args.match in output}
        for output, pid in watched.items():
            pss = sum(_memory_kb(p, "Pss") for p in _tree(pid)) // 1024
            peaks[output] = max(peaks.get(output, 0), pss)
        available = available_mib()
        lowest = available if lowest is None else min(lowest, available)
        state = {"peak_pss_mib": peaks, "lowest_available_mib": lowest, "updated": time.strftime("%F %T")}
        args.output.write_text(json.dumps(state, indent=1, sort_keys=True))
        time.sleep(args.every)


if __name__ == "__main__":
    main()
