#!/usr/bin/env bash
# Saves a study's compare folders: each one's results table and its runs' records (config, round and
# phase records; no frames or weights) compacted into one byte-stable archive, runs-records.tar.gz.
#   bash scripts/save_compare_records.sh STUDY   (outputs/STUDY/<folder>/ -> experiments/STUDY/records/<folder>/)
# Read the records back with: tar xzf experiments/STUDY/records/<folder>/runs-records.tar.gz -C <somewhere>
set -euo pipefail
STUDY=${1:?give the study, e.g. plateau-dagger-training-dev}
OUT=outputs/$STUDY
DEST=experiments/$STUDY/records
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
