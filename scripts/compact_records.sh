#!/usr/bin/env bash
# Compacts a study's runs' records (folders saved by save_run_records.sh) into byte-stable archives,
# runs-records.tar.gz, that `report --records` reads as it reads the folders: the toolkit's
# `records --action=compact` (lerobot_mtdagger/analysis/record_saving.py), kept under this name.
#   bash scripts/compact_records.sh experiments/STUDY/records
# Read an archive by hand with: tar xzf .../runs-records.tar.gz -C <somewhere>
set -euo pipefail
exec "${PYTHON:-$(dirname "$0")/../.venv/bin/python}" -m lerobot_mtdagger.cli records --action=compact \
  --source="${1:?give a study records folder, e.g. experiments/pixels-eval/records}"
