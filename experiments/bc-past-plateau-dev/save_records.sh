#!/usr/bin/env bash
# Copies every run's records from outputs/bc-past-plateau-dev/<training>/runs/ into
# records/<training>/<run>/ here (scripts/save_run_records.sh), so the numbers outlive outputs/ (not in
# git), then writes table.txt (the decision rule of run.sh, applied once every run has finished) from
# all records. Run from the repository root at any time.
set -euo pipefail
HERE=experiments/bc-past-plateau-dev
for TRAINING in outputs/bc-past-plateau-dev/*/; do
  [ -d "$TRAINING/runs" ] || continue
  bash scripts/save_run_records.sh "$TRAINING/runs" "$HERE/records/$(basename "$TRAINING")"
done
mkdir -p "$HERE/records"
.venv/bin/python "$HERE/table.py" "$HERE/records" > "$HERE/table.txt"
