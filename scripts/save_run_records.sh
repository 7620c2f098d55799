#!/usr/bin/env bash
# Copies the small JSON records of every run under RUNS (a folder of run folders) into DEST/<run>/:
# config.json, each round's meta/info.json (rounds/<round>/info.json) and each phase's training.json
# with its evaluation (policies/<round>/training.json), so a run's numbers outlive outputs/ (not in
# git). Unfinished runs give what they have. A run's records are replaced whole (a run restarted from
# nothing leaves none of its earlier records behind); runs not under RUNS keep theirs. From the
# repository root:
#   bash scripts/save_run_records.sh RUNS DEST
set -euo pipefail
RUNS=$1
DEST=$2
for RUN in "$RUNS"/*/; do
  [ -f "$RUN/config.json" ] || continue
  NAME=$(basename "$RUN")
  rm -rf "$DEST/$NAME"
  mkdir -p "$DEST/$NAME"
  cp "$RUN/config.json" "$DEST/$NAME/config.json"
  for K in "$RUN"/rounds/round-*; do
    [ -f "$K/meta/info.json" ] || continue
    mkdir -p "$DEST/$NAME/rounds/$(basename "$K")"
    cp "$K/meta/info.json" "$DEST/$NAME/rounds/$(basename "$K")/info.json"
  done
  for K in "$RUN"/policies/round-*; do
    [ -f "$K/training.json" ] || continue
    mkdir -p "$DEST/$NAME/policies/$(basename "$K")"
    cp "$K/training.json" "$DEST/$NAME/policies/$(basename "$K")/training.json"
  done
done
