#!/usr/bin/env bash
# Copies every run's records from outputs/drawers-eval/{dagger,bc}/runs into records/<run>/ here
# (scripts/save_run_records.sh), so a lost outputs/ costs only unfinished runs. Run from the repository
# root at any time; commit what it writes.
set -euo pipefail
for STAGE in dagger bc; do
  if [ -d "outputs/drawers-eval/$STAGE/runs" ]; then
    bash scripts/save_run_records.sh "outputs/drawers-eval/$STAGE/runs" experiments/drawers-eval/records
  fi
done
