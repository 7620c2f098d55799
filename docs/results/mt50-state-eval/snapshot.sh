#!/usr/bin/env bash
# The interim report of the MT50 study while it runs, into report/ here (report.md, figures, and the
# saved table results.csv/results.json/results_meta.json): commit it before a session stops, so that
# what the runs made survives the loss of outputs/ (`report --results` redraws it from the table).
# run.sh's last step overwrites it with the final report. From the repository root:
#   bash docs/results/mt50-state-eval/snapshot.sh
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/mt50-state-eval
variants=()
if [ -d "$OUT-bc-balanced/runs" ]; then
  variants=(--variants="{bc-balanced: $OUT-bc-balanced}")
fi
"$CLI" report --compare_dir="$OUT" "${variants[@]}" --levels='[0.6,0.8,0.9]' \
  --output_dir=docs/results/mt50-state-eval/report
