"""The drawers-preset-dev table and decision (rule fixed in run.sh before any run).

Run: ``.venv/bin/python experiments/drawers-preset-dev/table.py [RUNS_DIR]`` (default
``outputs/drawers-preset-dev``). Reads each run's phase records (``policies/round-XXX/training.json``);
a run that has not finished all 11 phases is listed and left out of the decision.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path
from statistics import fmean as mean

VARIANTS = ("fixed", "epochs")
SEEDS = (100, 101, 102)
PHASES = 11
LATE = range(6, 11)  # the phases the outcome averages
MARGIN = 0.02


def phase_records(run: Path) -> list[dict]:
    """The run's phase records in phase order (as many as are written)."""
    records = []
    for phase in range(PHASES):
        path = run / "policies" / f"round-{phase:03d}" / "training.json"
        if not path.is_file():
            break
        records.append(json.loads(path.read_text()))
    return records


def variant_rows(runs_dir: Path, variant: str) -> tuple[list[str], dict[int, list[dict]]]:
    """Markdown rows of one variant's seeds, and the finished runs' records by seed."""
    rows, finished = [], {}
    for seed in SEEDS:
        records = phase_records(runs_dir / f"{variant}-seed{seed}")
        if not records:
            rows.append(f"| {variant} | {seed} | not run | | | | |")
            continue
        success = [r["eval"]["mean"] for r in records]
        unseen = [(r.get("heldout_eval") or {}).get("mean") for r in records]
        seconds = sum(sum(r["timings"].values()) for r in records)
        late = mean([success[p] for p in LATE]) if len(records) == PHASES else None
        rows.append(
            f"| {variant} | {seed} | {len(records)} | "
            + " ".join(f"{s:.2f}" for s in success)
            + f" | {'' if late is None else f'{late:.3f}'} | "
            + " ".join("-" if u is None else f"{u:.2f}" for u in unseen)
            + f" | {seconds / 60:.0f} |"
        )
        if len(records) == PHASES:
            finished[seed] = records
    return rows, finished


def decision(finished: dict[str, dict[int, list[dict]]]) -> str:
    """The rule of run.sh on the finished runs (all 3 seeds of both variants needed)."""
    if any(len(finished[v]) < len(SEEDS) for v in VARIANTS):
        return "Decision: not yet (every variant needs its 3 seeds finished)"
    late = {
        v: mean([mean([finished[v][s][p]["eval"]["mean"] for p in LATE]) for s in SEEDS]) for v in VARIANTS
    }
    start = mean([finished["epochs"][s][0]["eval"]["mean"] for s in SEEDS])
    switch = late["epochs"] >= late["fixed"] + MARGIN and late["epochs"] >= start
    return (
        f"Decision: preset steps {'epochs' if switch else 'fixed'}: mean success over phases 6-10, "
        f"epochs {late['epochs']:.3f}, fixed {late['fixed']:.3f} (switch needs >= fixed + {MARGIN}); "
        f"epochs phase 0 {start:.3f}"
    )


def main() -> None:
    """Prints the table and the decision."""
    runs_dir = Path(sys.argv[1]) if len(sys.argv) > 1 else Path("outputs/drawers-preset-dev")
    print("| variant | seed | phases | success per phase 0-10 | mean 6-10 | unseen per phase | minutes |")
    print("|---|---:|---:|---|---:|---|---:|")
    finished = {}
    for variant in VARIANTS:
        rows, finished[variant] = variant_rows(runs_dir, variant)
        print("\n".join(rows))
    print()
    print(decision(finished))


if __name__ == "__main__":
    main()
