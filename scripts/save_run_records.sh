#!/usr/bin/env bash
# Copies the small JSON records of every run under RUNS (a folder of run folders) into DEST/<run>/, so a
# run's numbers outlive outputs/ (not in git): the toolkit's `records --action=save`
# (lerobot_mtdagger/analysis/record_saving.py), kept under this name for the studies' scripts.
# From the repository root (PYTHON: the interpreter with the package, default .venv/bin/python):
#   bash scripts/save_run_records.sh RUNS DEST
set -euo pipefail
exec "${PYTHON:-$(dirname "$0")/../.venv/bin/python}" -m lerobot_mtdagger.cli records --action=save \
  --source="${1:?give a folder of run folders}" --dest="${2:?give where the records go}"
