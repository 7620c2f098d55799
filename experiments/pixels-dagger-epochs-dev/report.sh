#!/usr/bin/env bash
# Each arm's report from its saved records, then run.sh's outcomes and rule (table.py) into table.txt.
# From the repository root, after save_records.sh.
set -euo pipefail
STUDY=experiments/pixels-dagger-epochs-dev
for ARM in epochs fixed; do
  .venv/bin/lerobot-mtdagger report --records="[$STUDY/records/$ARM]" --output_dir="$STUDY/report/$ARM"
done
# table.py imports experiments/lab
PYTHONPATH=experiments .venv/bin/python "$STUDY/table.py" > "$STUDY/table.txt"
