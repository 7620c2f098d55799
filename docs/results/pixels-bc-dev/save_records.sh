#!/usr/bin/env bash
# Copies each finished run's training record (its evaluation included) from outputs/pixels-bc-dev/
# into records/<sampling>/<run>/training.json here, so the numbers outlive outputs/ (not in git), then
# writes table.txt from all records. Run from the repository root, at any time (finished runs only).
set -euo pipefail
HERE=docs/results/pixels-bc-dev
for RECORD in outputs/pixels-bc-dev/*/runs/*/policies/round-000/training.json; do
  [ -f "$RECORD" ] || continue
  RUN=$(basename "$(dirname "$(dirname "$(dirname "$RECORD")")")")
  SAMPLING=$(basename "$(dirname "$(dirname "$(dirname "$(dirname "$(dirname "$RECORD")")")")")")
  mkdir -p "$HERE/records/$SAMPLING/$RUN"
  cp "$RECORD" "$HERE/records/$SAMPLING/$RUN/training.json"
done
.venv/bin/python "$HERE/table.py" "$HERE/records" > "$HERE/table.txt"
