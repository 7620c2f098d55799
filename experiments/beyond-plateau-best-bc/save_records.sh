#!/usr/bin/env bash
# Copies every run's records from outputs/beyond-plateau-best-bc/<training>/runs/ into
# records/<training>/<run>/ here (scripts/save_run_records.sh), so the numbers outlive outputs/ (not in
# git), then writes table.txt (table.py) from them. Run from the repository root at any time.
set -euo pipefail
HERE=experiments/beyond-plateau-best-bc
for TRAINING in outputs/beyond-plateau-best-bc/*/; do
  [ -d "$TRAINING/runs" ] || continue
  bash scripts/save_run_records.sh "$TRAINING/runs" "$HERE/records/$(basename "$TRAINING")"
done
mkdir -p "$HERE/records"
.venv/bin/python "$HERE/table.py" > "$HERE/table.txt"
