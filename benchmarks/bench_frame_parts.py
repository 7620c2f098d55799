"""A training batch gathered from rounds kept apart (``FrameParts``) against one concatenated tensor.

The frames of the pixel preset run's six rounds (``docs/benchmarks.md``: 9 820 to 32 217 frames of
84 x 84 x 3 uint8 each, 152 494 in all, 3.1 GB), random batches of 64 frames as a training step draws
them, on one torch thread; the two ways interleaved, medians over the repeats. Target: gathering
from the parts is no slower than indexing the concatenated tensor (ratio <= 1.0), so holding the
rounds once costs the training step nothing.

Usage: ``.venv/bin/python benchmarks/bench_frame_parts.py [--batches 300] [--repeats 5]``
"""

from __future__ import annotations

import argparse
import statistics
import time

import torch

from lerobot_mtdagger.runner.training.frame_parts import FrameParts

ROUND_FRAMES = (9820, 16464, 30317, 32217, 31786, 31890)
IMAGE = (84, 84, 3)
BATCH = 64
TARGET = 1.0


def time_batches(frames: torch.Tensor | FrameParts, batches: list[torch.Tensor]) -> float:
    """Mean seconds per batch gathered from ``frames``."""
    start = time.perf_counter()
    for index in batches:
        frames[index]
    return (time.perf_counter() - start) / len(batches)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--batches", type=int, default=300)
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()
    torch.set_num_threads(1)
    generator = torch.Generator().manual_seed(0)
    parts = [torch.randint(0, 256, (n, *IMAGE), dtype=torch.uint8, generator=generator) for n in ROUND_FRAMES]
    joined, whole = FrameParts(parts), torch.cat(parts)
    batches = [torch.randint(len(whole), (BATCH,), generator=generator) for _ in range(args.batches)]
    times: dict[str, list[float]] = {"concatenated": [], "parts": []}
    for repeat in range(args.repeats):
        order = [("concatenated", whole), ("parts", joined)]
        for name, frames in order if repeat % 2 == 0 else order[::-1]:
            times[name].append(time_batches(frames, batches))
    medians = {name: statistics.median(values) for name, values in times.items()}
    for name, value in medians.items():
        print(f"{name}: {value * 1e6:.0f} us per batch of {BATCH} (median of {args.repeats})")
    ratio = medians["parts"] / medians["concatenated"]
    print(f"{'PASS' if ratio <= TARGET else 'FAIL'}: parts / concatenated = {ratio:.2f} (target <= {TARGET})")


if __name__ == "__main__":
    main()
