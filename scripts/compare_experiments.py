"""Compares two experiment folders: same allocations, same episodes, same metrics?

Usage::

    .venv/bin/python scripts/compare_experiments.py OLD_DIR NEW_DIR [--ignore-config KEY ...] [--strict]

Reads the stored JSON directly (no class of this package but the config layout), so it also compares
folders written by older versions. Per round it compares the round's record (every field except
``config``, compared separately option by option), the data files (sha256 of each parquet file's
decoded table), and per training phase ``training.json`` and the policy weights. Prints one line per
difference and exits 1 if there is any.

By default it leaves out what never changes a result: the options a resume may change
(``RESULT_NEUTRAL_OPTIONS``: ``resume``, ``progress``, ``output_dir``, worker counts and backend,
``preset``, ``policy.device``) and, in ``training.json``, ``timings`` and ``environment`` (where it
ran). ``--strict`` compares those too; ``--ignore-config KEY ...`` leaves out more options (dotted
paths, e.g. ones renamed on purpose). A record's ``ledger`` flag (whether it was committed into a
ledger) is never compared.
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys
from pathlib import Path

import pyarrow.parquet as pq
from safetensors.numpy import load_file

from lerobot_mtdagger.datasets.config_layout import RESULT_NEUTRAL_OPTIONS, flatten
from lerobot_mtdagger.datasets.migrations import migrate_run_config

PROVENANCE_FIELDS = {"timings", "environment"}
"""``training.json`` fields that say how and where a phase ran, not what it gave."""

STORAGE_FIELDS = {"ledger"}
"""Record fields that say how a record is stored (committed into a ledger), never compared."""


def round_record(root: Path) -> dict:
    """A round's record: ``meta/mtdagger.json``, or ``meta/info.json``'s mirror in older rounds."""
    sidecar = root / "meta" / "mtdagger.json"
    if sidecar.is_file():
        return json.loads(sidecar.read_text())
    return json.loads((root / "meta" / "info.json").read_text())["mtdagger"]


def table_digest(path: Path) -> str:
    """sha256 of a parquet file's rows (the encoded file may differ in metadata only)."""
    table = pq.read_table(path)
    return hashlib.sha256(table.to_pandas().to_json().encode()).hexdigest()


def compare_dicts(old: dict, new: dict, where: str, skip: set[str]) -> list[str]:
    """One line per key whose value differs."""
    keys = sorted((set(old) | set(new)) - skip)
    return [f"{where}.{k}: {old.get(k)!r} != {new.get(k)!r}" for k in keys if old.get(k) != new.get(k)]


def compare_round(old: Path, new: Path, ignore_config: set[str]) -> list[str]:
    """Differences of one round's record and data."""
    records = [round_record(p) for p in (old, new)]
    problems = compare_dicts(records[0], records[1], old.name, {"config", *STORAGE_FIELDS})
    # Configs compared option by option, in today's layout (a flat stored config is migrated).
    configs = [flatten(migrate_run_config(r["config"])) for r in records]
    problems += compare_dicts(configs[0], configs[1], f"{old.name}.config", ignore_config)
    files = [sorted(p.relative_to(root) for p in (root / "data").rglob("*.parquet")) for root in (old, new)]
    if files[0] != files[1]:
        problems.append(f"{old.name}: data files {files[0]} != {files[1]}")
    for relative in files[0]:
        if relative in files[1] and table_digest(old / relative) != table_digest(new / relative):
            problems.append(f"{old.name}: frames of {relative} differ")
    return problems


def compare_phase(old: Path, new: Path, skip: set[str]) -> list[str]:
    """Differences of one training phase's record (less the ``skip`` fields) and weights."""
    records = [json.loads((p / "training.json").read_text()) for p in (old, new)]
    problems = compare_dicts(records[0], records[1], f"policy {old.name}", skip)
    weights = [load_file(str(p / "model.safetensors")) for p in (old, new)]
    for name in sorted(set(weights[0]) | set(weights[1])):
        if name not in weights[0] or name not in weights[1] or (weights[0][name] != weights[1][name]).any():
            problems.append(f"policy {old.name}: weight {name} differs")
    return problems


def main() -> int:
    """Parses the arguments, prints the differences, returns the exit status."""
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("old", type=Path)
    parser.add_argument("new", type=Path)
    parser.add_argument(
        "--ignore-config", nargs="*", default=[], help="more config options to leave out (dotted paths)"
    )
    parser.add_argument(
        "--strict",
        action="store_true",
        help="also compare what never changes a result (resume, workers, ...)",
    )
    args = parser.parse_args()
    ignore = set(args.ignore_config) | (set() if args.strict else {*RESULT_NEUTRAL_OPTIONS})
    phase_skip = ({"timings"} if args.strict else PROVENANCE_FIELDS) | STORAGE_FIELDS
    problems = []
    rounds = [sorted(p.name for p in (root / "rounds").glob("round-*")) for root in (args.old, args.new)]
    phases = [sorted(p.name for p in (root / "policies").glob("round-*")) for root in (args.old, args.new)]
    if rounds[0] != rounds[1] or phases[0] != phases[1]:
        problems.append(f"committed rounds/phases differ: {rounds} {phases}")
    for name in rounds[0]:
        problems += compare_round(args.old / "rounds" / name, args.new / "rounds" / name, ignore)
    for name in phases[0]:
        problems += compare_phase(args.old / "policies" / name, args.new / "policies" / name, phase_skip)
    for problem in problems:
        print(problem)
    counts = f"{len(rounds[0])} rounds, {len(phases[0])} phases"
    print(f"{args.old} vs {args.new}: {counts}, {len(problems)} difference(s)")
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
