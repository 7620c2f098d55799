#!/usr/bin/env bash
# Copies every run's records from outputs/pixels-eval/ into records/<run>/ here
# (scripts/save_run_records.sh), so a lost outputs/ costs only unfinished runs. Run from the repository
# root at any time; commit what it writes.
set -euo pipefail
bash scripts/save_run_records.sh outputs/pixels-eval/runs experiments/pixels-eval/records
