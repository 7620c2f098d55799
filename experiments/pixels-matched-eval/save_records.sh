#!/usr/bin/env bash
# Saves the study's results tables and runs' records (one archive per seed's compare folder,
# scripts/save_compare_records.sh: outputs/pixels-matched-eval/seed<k>/ -> records/seed<k>/) and the
# decision run.sh read (outputs/pixels-matched-eval/decision.txt -> records/decision.txt), then writes
# table.txt (table.py, from the saved records alone). From ../main, after each session:
#   bash experiments/pixels-matched-eval/save_records.sh
set -euo pipefail
HERE=experiments/pixels-matched-eval
bash scripts/save_compare_records.sh pixels-matched-eval
if [ -f outputs/pixels-matched-eval/decision.txt ]; then
  mkdir -p "$HERE/records"
  cp outputs/pixels-matched-eval/decision.txt "$HERE/records/decision.txt"
fi
PYTHONPATH=experiments .venv/bin/python "$HERE/table.py" > "$HERE/table.txt"
