#!/usr/bin/env bash
# Copies every run's records from outputs/drawers-training-spread-dev/ into records/<run>/ here
# (scripts/save_run_records.sh). Run from the repository root at any time; commit what it writes.
set -euo pipefail
bash scripts/save_run_records.sh outputs/drawers-training-spread-dev experiments/drawers-training-spread-dev/records
