#!/usr/bin/env bash
# Copies the small JSON records of each run (round records, phase records) from outputs/visual-dev/
# into records/<run>/ here, so the numbers outlive outputs/ (not in git). Run from the repository root.
set -euo pipefail
HERE=docs/results/visual-collapse-dev
for RUN in outputs/visual-dev/*-seed*/; do
  NAME=$(basename "$RUN")
  for K in "$RUN"/rounds/round-*; do
    [ -d "$K" ] || continue
    mkdir -p "$HERE/records/$NAME/rounds/$(basename "$K")"
    cp "$K/meta/info.json" "$HERE/records/$NAME/rounds/$(basename "$K")/info.json"
  done
  for K in "$RUN"/policies/round-*; do
    [ -d "$K" ] || continue
    mkdir -p "$HERE/records/$NAME/policies/$(basename "$K")"
    cp "$K/training.json" "$HERE/records/$NAME/policies/$(basename "$K")/training.json"
  done
done
.venv/bin/python "$HERE/rounds_summary.py" outputs/visual-dev/*-seed*/ > "$HERE/rounds_summary.txt"
