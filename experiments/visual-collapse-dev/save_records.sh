#!/usr/bin/env bash
# Copies the small JSON records of each run (scripts/save_run_records.sh) from outputs/visual-dev/
# into records/<run>/ here, with the run's rounds_summary.py table, so the numbers outlive outputs/ (not
# in git); rounds_summary.txt joins the tables of every run in records/. Run from the repository root.
set -euo pipefail
HERE=experiments/visual-collapse-dev
bash scripts/save_run_records.sh outputs/visual-dev "$HERE/records"
for RUN in outputs/visual-dev/*-seed*/; do
  NAME=$(basename "$RUN")
  # This run's table, kept beside its records: the joined file below also keeps the runs whose
  # outputs/ are gone (a new checkout has none).
  .venv/bin/python "$HERE/rounds_summary.py" "outputs/visual-dev/$NAME" | sed -e '1{/^$/d}' \
    > "$HERE/records/$NAME/rounds_summary.txt"
done
for SUMMARY in "$HERE"/records/*/rounds_summary.txt; do
  echo
  cat "$SUMMARY"
done > "$HERE/rounds_summary.txt"
# The unseen-rules evaluations (unseen-rules.sh) and their table.
if ls outputs/visual-dev/unseen-rules/*.json > /dev/null 2>&1; then
  mkdir -p "$HERE/unseen-rules"
  cp outputs/visual-dev/unseen-rules/*.json "$HERE/unseen-rules/"
  .venv/bin/python "$HERE/unseen_rules_summary.py" "$HERE/unseen-rules" > "$HERE/unseen-rules/table.txt"
fi
# The kitchen re-evaluations (reeval-kitchen.sh) and their table.
if ls outputs/visual-dev/reeval-kitchen/*.json > /dev/null 2>&1; then
  mkdir -p "$HERE/reeval-kitchen"
  cp outputs/visual-dev/reeval-kitchen/*.json "$HERE/reeval-kitchen/"
  .venv/bin/python "$HERE/reeval_summary.py" "$HERE/reeval-kitchen" > "$HERE/reeval-kitchen/table.txt"
fi
