#!/usr/bin/env bash
# Copies every run's records from outputs/drawers-preset-dev/ into records/<run>/ here
# (../save_run_records.sh), so a lost outputs/ costs only unfinished runs. From the repository root at
# any time; commit what it writes. table.py reads records/ as it reads the run folders:
#   .venv/bin/python docs/results/drawers-preset-dev/table.py docs/results/drawers-preset-dev/records
set -euo pipefail
bash docs/results/save_run_records.sh outputs/drawers-preset-dev docs/results/drawers-preset-dev/records
