#!/usr/bin/env bash
# Copies every run's records from outputs/drawers-training-spread-dev/ into records/<run>/ here
# (../save_run_records.sh). Run from the repository root at any time; commit what it writes.
set -euo pipefail
bash docs/results/save_run_records.sh outputs/drawers-training-spread-dev docs/results/drawers-training-spread-dev/records
