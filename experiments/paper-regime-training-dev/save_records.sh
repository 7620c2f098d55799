#!/usr/bin/env bash
# Saves each compare folder's results table and its runs' records (config, round and phase records; no
# frames or weights), compacted into one archive per folder (runs-records.tar.gz, byte-stable), into
# records/, from ../main, after each session:
#   bash experiments/paper-regime-training-dev/save_records.sh
# Read the records back with: tar xzf records/<folder>/runs-records.tar.gz -C <somewhere>
set -euo pipefail
OUT=outputs/paper-regime-training-dev
DEST=experiments/paper-regime-training-dev/records
STAGE=$(mktemp -d)
trap 'rm -rf "$STAGE"' EXIT
for COMPARE in "$OUT"/*/; do
  NAME=$(basename "$COMPARE")
  [ -d "$COMPARE/runs" ] || continue
  mkdir -p "$DEST/$NAME"
  [ -f "$COMPARE/results.csv" ] && cp "$COMPARE/results.csv" "$DEST/$NAME/"
  bash scripts/save_run_records.sh "$COMPARE/runs" "$STAGE/$NAME" > /dev/null
  tar --sort=name --mtime=@0 --owner=0 --group=0 --numeric-owner -C "$STAGE/$NAME" -cf - . \
    | gzip -n > "$DEST/$NAME/runs-records.tar.gz"
done
