#!/usr/bin/env bash
# Copies every run's records from outputs/pixels-bc-dev/<sampling>/runs/ into
# records/<sampling>/<run>/ here (scripts/save_run_records.sh), so the numbers outlive outputs/ (not in
# git), then writes table.txt from all records (finished runs only). Run from the repository root.
set -euo pipefail
HERE=experiments/pixels-bc-dev
for SAMPLING in outputs/pixels-bc-dev/*/; do
  [ -d "$SAMPLING/runs" ] || continue
  bash scripts/save_run_records.sh "$SAMPLING/runs" "$HERE/records/$(basename "$SAMPLING")"
done
.venv/bin/python "$HERE/table.py" "$HERE/records" > "$HERE/table.txt"
