#!/usr/bin/env bash
# Copies each finished run's training record (its evaluation included) from
# outputs/bc-past-plateau-dev/ into records/<training>/<run>/training.json here, so the numbers
# outlive outputs/ (not in git). Run from the repository root at any time (finished runs only).
set -euo pipefail
HERE=docs/results/bc-past-plateau-dev
for RECORD in outputs/bc-past-plateau-dev/*/runs/*/policies/round-000/training.json; do
  [ -f "$RECORD" ] || continue
  RUN_DIR=$(dirname "$(dirname "$(dirname "$RECORD")")")
  TRAINING=$(basename "$(dirname "$(dirname "$RUN_DIR")")")
  mkdir -p "$HERE/records/$TRAINING/$(basename "$RUN_DIR")"
  cp "$RECORD" "$HERE/records/$TRAINING/$(basename "$RUN_DIR")/training.json"
done
