"""Parsing a run's options: draccus as it comes against draccus with class sources read once.

Run: ``.venv/bin/python benchmarks/bench_parse.py`` (``--repeats``). draccus builds each option's help
text from its class's source; on Python 3.11 ``inspect.getsource`` of a class parses the class's
whole module, and draccus asks once per field (and, for the LeRobot students' options, which have no
source, once per inherited field). ``utils/parsing.cache_dataclass_sources`` keeps each class's source
(or its absence). Both are timed in ONE run, interleaved; the ratio is what counts. Target: the cached
parse at least 5x faster (it is paid by every ``run``, ``compare`` run and test that parses a config).
"""

from __future__ import annotations

import argparse
import inspect
import statistics
import time

import draccus
from draccus.wrappers import docstring as draccus_docstring

from lerobot_mtdagger.runner.configs import RunConfig
from lerobot_mtdagger.utils import parsing

TARGET = 5.0
OPTIONS = ["--suite.name=toy", "--dagger.rounds=2", "--output_dir=/tmp/unused"]


def parse_seconds(cached: bool) -> float:
    """Seconds to parse ``OPTIONS`` into a ``RunConfig``, with or without the source cache (cleared)."""
    parsing._class_source.cache_clear()
    draccus_docstring.inspect = parsing._InspectWithClassSourceCache() if cached else inspect
    start = time.perf_counter()
    draccus.parse(RunConfig, args=OPTIONS)
    return time.perf_counter() - start


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    times: dict[bool, list[float]] = {False: [], True: []}
    for _ in range(args.repeats):
        for cached in (False, True):
            times[cached].append(parse_seconds(cached))
    plain, cached = statistics.median(times[False]), statistics.median(times[True])
    ratio = plain / cached
    print(f"draccus as it comes: {plain * 1000:.0f} ms per parse (median of {args.repeats})")
    print(f"class sources cached: {cached * 1000:.0f} ms per parse (a fresh cache each time)")
    print(f"speed-up {ratio:.1f}x: {'PASS' if ratio >= TARGET else 'FAIL'} (target >= {TARGET:g}x)")


if __name__ == "__main__":
    main()
