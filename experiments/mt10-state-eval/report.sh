#!/usr/bin/env bash
# The combined report of the MT10 evaluation-seed study, once run.sh has finished: every method of
# outputs/mt10-state-eval with BC trained with balanced sampling as a second baseline
# (`bc-balanced`), written into this folder (report.md, results.csv/json, figures). From the
# repository root:
#   bash docs/results/mt10-state-eval/report.sh
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/mt10-state-eval
"$CLI" report --compare_dir="$OUT" --variants="{bc-balanced: $OUT-bc-balanced}" \
  --levels='[0.6,0.8,0.9]' --output_dir=docs/results/mt10-state-eval/report
