#!/usr/bin/env bash
# Copies each run's small JSON records (round 0's meta/info.json, the BC phase's training.json) from
# outputs/placement-dev/ into records/<run>/ here, so the numbers outlive outputs/ (not in git), and
# writes table.txt. Run from the repository root.
set -euo pipefail
HERE=experiments/drawer-placement-dev
for RUN in outputs/placement-dev/bc-*-seed*/; do
  NAME=$(basename "$RUN")
  [ -f "$RUN/policies/round-000/training.json" ] || continue
  mkdir -p "$HERE/records/$NAME/rounds/round-000" "$HERE/records/$NAME/policies/round-000"
  cp "$RUN/rounds/round-000/meta/info.json" "$HERE/records/$NAME/rounds/round-000/info.json"
  cp "$RUN/policies/round-000/training.json" "$HERE/records/$NAME/policies/round-000/training.json"
done
.venv/bin/python "$HERE/table.py" experiments/visual-collapse-dev/records/hold-seed100 "$HERE"/records/bc-*/ > "$HERE/table.txt"
