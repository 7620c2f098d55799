#!/usr/bin/env bash
# Copies every run's records from outputs/bc-past-plateau-dev/<training>/runs/ into
# records/<training>/<run>/ here (../save_run_records.sh), so the numbers outlive outputs/ (not in
# git). Run from the repository root at any time.
set -euo pipefail
for TRAINING in outputs/bc-past-plateau-dev/*/; do
  [ -d "$TRAINING/runs" ] || continue
  bash docs/results/save_run_records.sh "$TRAINING/runs" \
    "docs/results/bc-past-plateau-dev/records/$(basename "$TRAINING")"
done
