#!/usr/bin/env bash
# Copies every run's records from outputs/pixels-dagger-epochs-dev/<arm>/ into records/<arm>/ here
# (scripts/save_run_records.sh), so a lost outputs/ costs only unfinished runs. From the repository root
# at any time; commit what it writes.
set -euo pipefail
for ARM in epochs fixed; do
  if [ -d "outputs/pixels-dagger-epochs-dev/$ARM/runs" ]; then
    bash scripts/save_run_records.sh "outputs/pixels-dagger-epochs-dev/$ARM/runs" \
      "experiments/pixels-dagger-epochs-dev/records/$ARM"
  fi
done
