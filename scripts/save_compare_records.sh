#!/usr/bin/env bash
# Saves a study's compare folders: each one's results table and its runs' records (config, round and
# phase records; no frames or weights) compacted into one byte-stable archive, runs-records.tar.gz.
#   bash scripts/save_compare_records.sh STUDY   (outputs/STUDY/<folder>/ -> experiments/STUDY/records/<folder>/)
# Read the records back with: tar xzf experiments/STUDY/records/<folder>/runs-records.tar.gz -C <somewhere>
# Runs an earlier save archived and outputs/ no longer holds (a machine that kept no outputs/ between
# sessions) stay in the archive; a run outputs/ holds replaces its archived records whole. When the
# archive then holds runs the compare folder did not run, that folder's results.csv would not show them:
# it is not saved (an earlier one is removed), and `lerobot-mtdagger report --records=<the folder>`
# makes the table of every archived run.
set -euo pipefail
STUDY=${1:?give the study, e.g. plateau-dagger-training-dev}
OUT=outputs/$STUDY
DEST=experiments/$STUDY/records
STAGE=$(mktemp -d)
trap 'rm -rf "$STAGE"' EXIT
for COMPARE in "$OUT"/*/; do
  NAME=$(basename "$COMPARE")
  [ -d "$COMPARE/runs" ] || continue
  mkdir -p "$DEST/$NAME" "$STAGE/$NAME"
  ARCHIVE=$DEST/$NAME/runs-records.tar.gz
  [ -f "$ARCHIVE" ] && tar xzf "$ARCHIVE" -C "$STAGE/$NAME"
  bash scripts/save_run_records.sh "$COMPARE/runs" "$STAGE/$NAME" > /dev/null
  KEPT=""
  for RUN in "$STAGE/$NAME"/*/; do
    [ -f "$RUN/config.json" ] && [ ! -f "$COMPARE/runs/$(basename "$RUN")/config.json" ] && KEPT="$KEPT $(basename "$RUN")"
  done
  if [ -n "$KEPT" ]; then
    rm -f "$DEST/$NAME/results.csv"
    echo "$DEST/$NAME: kept the archived runs$KEPT (not in $COMPARE); results.csv not saved:" \
      "lerobot-mtdagger report --records=$DEST/$NAME makes the table of every run"
  elif [ -f "$COMPARE/results.csv" ]; then
    cp "$COMPARE/results.csv" "$DEST/$NAME/"
  fi
  tar --sort=name --mtime=@0 --owner=0 --group=0 --numeric-owner -C "$STAGE/$NAME" -cf - . \
    | gzip -n > "$ARCHIVE"
done
