#!/usr/bin/env bash
# Draws one report of need, uniform, plain BC (../beyond-plateau-eval, seeds 0-4) and the best BC
# (this study's runs, reported as the method `bc-cosine`), from the saved tables alone. Written on
# 2026-11-27 after this study's results (a presentation step: no run, setting or outcome changes; the
# fixed outcomes are table.py's). `report --results` names a table's methods as their runs did, and
# both studies' BC runs are `bc`, so this study's table is first copied with its method renamed.
# Run from the repository root, once outputs/beyond-plateau-best-bc/cosine/results.json exists.
set -euo pipefail
HERE=docs/results/beyond-plateau-best-bc
SEEDS=docs/results/beyond-plateau-eval/seeds
RENAMED=$HERE/report/bc-cosine
mkdir -p "$RENAMED"
.venv/bin/python - "$RENAMED" << 'PY'
import json
import sys

source, target = "outputs/beyond-plateau-best-bc/cosine", sys.argv[1]
rows = json.load(open(f"{source}/results.json"))
for row in rows:
    row["method"] = "bc-cosine"
meta = json.load(open(f"{source}/results_meta.json"))
meta["configs"] = {"bc-cosine": meta["configs"].pop("bc")}
json.dump(rows, open(f"{target}/results.json", "w"), indent=1)
json.dump(meta, open(f"{target}/results_meta.json", "w"), indent=1)
PY
.venv/bin/lerobot-mtdagger report \
  --results="[$SEEDS/seed0,$SEEDS/seed1,$SEEDS/seed2,$SEEDS/seed3,$SEEDS/seed4,$RENAMED]" \
  --levels='[0.9,0.95]' --output_dir="$HERE/report"
