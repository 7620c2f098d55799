#!/usr/bin/env bash
# Copies what outputs/paper-regime-calibration-dev/ holds into records/ here: the expert sweep
# (expert-success.json and .md), each choice and BC check, and the records of every BC run
# (scripts/save_run_records.sh), so a lost outputs/ costs only unfinished runs. From the repository
# root at any time; commit what it writes.
set -euo pipefail
OUT=outputs/paper-regime-calibration-dev
DEST=experiments/paper-regime-calibration-dev/records
mkdir -p "$DEST"
for FILE in "$OUT"/expert-success.json "$OUT"/expert-success.md "$OUT"/choice-*.txt "$OUT"/bc-check-*.txt; do
  [ -f "$FILE" ] && cp "$FILE" "$DEST/"
done
for RUNS in "$OUT"/bc-noise-*/runs; do
  [ -d "$RUNS" ] || continue
  bash scripts/save_run_records.sh "$RUNS" "$DEST/$(basename "$(dirname "$RUNS")")"
done
