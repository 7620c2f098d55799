#!/usr/bin/env bash
# Copies the study's small outputs (the noise map, the fresh check, the kept tasks, the BC check) and
# its BC runs' records (no frames or weights) into records/, from ../main, after each session:
#   bash experiments/paper-regime-pertask-dev/save_records.sh
set -euo pipefail
OUT=outputs/paper-regime-pertask-dev
DEST=experiments/paper-regime-pertask-dev/records
mkdir -p "$DEST"
for FILE in "$OUT"/noise-by-task.json "$OUT"/noise-by-task.md "$OUT"/check.json "$OUT"/check.md \
  "$OUT"/kept.txt "$OUT"/bc-check.txt; do
  [ -f "$FILE" ] && cp "$FILE" "$DEST/"
done
if [ -d "$OUT/bc/runs" ]; then
  bash scripts/save_run_records.sh "$OUT/bc/runs" "$DEST/bc"
fi
