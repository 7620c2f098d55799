#!/usr/bin/env bash
# Copies the small JSON records of every run (each round's meta/info.json, each phase's training.json
# with its evaluation) from outputs/pixels-eval/ into records/<run>/ here, so a lost outputs/ (not in
# git) costs only unfinished runs. Run from the repository root at any time; commit what it writes.
set -euo pipefail
HERE=docs/results/pixels-eval
for RUN in outputs/pixels-eval/runs/*/; do
  [ -d "$RUN" ] || continue
  NAME=$(basename "$RUN")
  [ -f "$RUN/config.json" ] && mkdir -p "$HERE/records/$NAME" && cp "$RUN/config.json" "$HERE/records/$NAME/"
  for K in "$RUN"/rounds/round-*; do
    [ -f "$K/meta/info.json" ] || continue
    mkdir -p "$HERE/records/$NAME/rounds/$(basename "$K")"
    cp "$K/meta/info.json" "$HERE/records/$NAME/rounds/$(basename "$K")/info.json"
  done
  for K in "$RUN"/policies/round-*; do
    [ -f "$K/training.json" ] || continue
    mkdir -p "$HERE/records/$NAME/policies/$(basename "$K")"
    cp "$K/training.json" "$HERE/records/$NAME/policies/$(basename "$K")/training.json"
  done
done
