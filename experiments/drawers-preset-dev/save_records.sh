#!/usr/bin/env bash
# Copies every run's records from outputs/drawers-preset-dev/ into records/<run>/ here
# (scripts/save_run_records.sh), so a lost outputs/ costs only unfinished runs. From the repository root at
# any time; commit what it writes. table.py reads records/ as it reads the run folders:
#   .venv/bin/python experiments/drawers-preset-dev/table.py experiments/drawers-preset-dev/records
set -euo pipefail
bash scripts/save_run_records.sh outputs/drawers-preset-dev experiments/drawers-preset-dev/records
