#!/usr/bin/env bash
# Saves the study's results tables and runs' records (one archive per compare folder,
# scripts/save_compare_records.sh) and the decision run.sh read (outputs/plateau-dagger-eval/decision.txt
# -> records/decision.txt), then writes table.txt (table.py, from the saved records alone). From ../main:
#   bash experiments/plateau-dagger-eval/save_records.sh
set -euo pipefail
HERE=experiments/plateau-dagger-eval
bash scripts/save_compare_records.sh plateau-dagger-eval
if [ -f outputs/plateau-dagger-eval/decision.txt ]; then
  mkdir -p "$HERE/records"
  cp outputs/plateau-dagger-eval/decision.txt "$HERE/records/decision.txt"
fi
PYTHONPATH=experiments .venv/bin/python "$HERE/table.py" > "$HERE/table.txt"
