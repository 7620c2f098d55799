"""The replay bench's prediction beside what the evaluation-seed studies of the same settings measured.

Usage: ``python bench_check.py OUT`` where OUT holds ``replay-paper.json`` and ``replay-pixels.json``
(written by ``run.sh`` from development curves only). Prints a markdown table: for need - uniform in
mean success over the budgets, the bench's predicted effect and the SD of one replicate's paired
difference, beside the measured effect, its interval and its SD over seeds, and whether the measured
interval holds the prediction.

The measured numbers are copied from the studies' READMEs (the pre-specified primary or secondary of
each): they were run before the bench existed, with settings the bench replays in part only (it has
no training noise, no DAgger states and no sampling).
"""

from __future__ import annotations

import json
import math
import sys
from dataclasses import dataclass
from pathlib import Path

from scipy import stats


@dataclass(frozen=True)
class Measured:
    """need - uniform as an evaluation-seed study measured it.

    Attributes:
        study: The study folder (under ``experiments/``).
        seeds: Its evaluation seeds.
        estimate: The paired mean.
        low: The 95% t interval's lower end.
        high: Its upper end.
        seed_sd: The SD over seeds of the paired difference.
    """

    study: str
    seeds: int
    estimate: float
    low: float
    high: float
    seed_sd: float


MEASURED = {
    "paper": Measured("paper-regime-eval", 3, 0.007, -0.035, 0.049, 0.017),
    "pixels": Measured("pixels-matched-eval", 3, 0.011, -0.008, 0.029, 0.0074),
}
ARM = "need"


def predicted(replay: dict) -> tuple[float, float, float, float]:
    """The bench's need - uniform: mean over replicates, 95% interval, SD of one paired difference.

    The SD is the bench's evaluation noise only (its arms share random draws, as seeds pair a study).
    """
    arms = {arm["label"]: arm for arm in replay["arms"]}
    effect, low, high = arms[ARM]["vs_uniform"]
    replicates = replay["setting"]["replicates"]
    sd = (high - low) / 2 / stats.t.ppf(0.975, replicates - 1) * math.sqrt(replicates)
    return effect, low, high, sd


def lines(folder: Path) -> list[str]:
    """The table's lines."""
    out = [
        "| setting | bench: need - uniform [95% over replicates] | bench SD of a paired difference "
        "| measured [95% t] (study, seeds) | measured SD over seeds "
        "| measured interval holds the prediction |",
        "|---|---:|---:|---:|---:|---|",
    ]
    for name, measured in MEASURED.items():
        replay = json.loads((folder / f"replay-{name}.json").read_text())
        effect, low, high, sd = predicted(replay)
        holds = "yes" if measured.low <= effect <= measured.high else "no"
        out.append(
            f"| {name} | {effect:+.3f} [{low:+.3f}, {high:+.3f}] | {sd:.4f} | {measured.estimate:+.3f} "
            f"[{measured.low:+.3f}, {measured.high:+.3f}] ({measured.study}, {measured.seeds}) "
            f"| {measured.seed_sd:.4f} | {holds} |"
        )
    return out


if __name__ == "__main__":
    print("\n".join(lines(Path(sys.argv[1]))))
