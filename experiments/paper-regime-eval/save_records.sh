#!/usr/bin/env bash
# Saves the study's settings (read once from the development study before its first run), results
# tables and runs' records (one archive per compare folder), from ../main:
#   bash experiments/paper-regime-eval/save_records.sh
set -euo pipefail
mkdir -p experiments/paper-regime-eval/records
cp outputs/paper-regime-eval/settings.txt experiments/paper-regime-eval/records/settings.txt
exec bash scripts/save_compare_records.sh paper-regime-eval
