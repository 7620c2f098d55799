#!/usr/bin/env bash
# The toolkit's own report of the study (figures and report.md, `lerobot-mtdagger report`): this study's
# DAgger runs (records/seed<k>/runs-records.tar.gz) beside pixels-eval's BC runs, the BC this study
# reuses (extracted from ../pixels-eval/records/runs-records.tar.gz; pixels-eval's own DAgger runs,
# the earlier protocol, are left out: they would share the method names). Written after the nine runs'
# records were saved; the pre-specified outcomes are table.py's (table.txt), and what report.md adds
# (demos to reach 0.6 and 0.7, pixels-eval's levels; per-task gaps; stability) is descriptive, not one of
# them. From ../main:
#   bash experiments/pixels-matched-eval/report.sh [OUTPUT_DIR]   (default experiments/pixels-matched-eval/report)
set -euo pipefail
HERE=experiments/pixels-matched-eval
OUT=${1:-$HERE/report}
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
bc=$(mktemp -d)
trap 'rm -rf "$bc"' EXIT
tar -xzf experiments/pixels-eval/records/runs-records.tar.gz -C "$bc" --wildcards 'bc-*'
mkdir -p "$OUT"
"$CLI" report --records="[$HERE/records,$bc]" --output_dir="$OUT" --levels='[0.6,0.7]' > /dev/null  # pixels-eval's levels; report.md holds the table
