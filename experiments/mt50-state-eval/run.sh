#!/usr/bin/env bash
# MetaWorld MT50 state (the `metaworld-state` preset: 3 initial demos per task, 10 DAgger rounds of
# 3 per task, up to 33 demos per task, 3 000 training steps per phase at batch 1024) on the
# EVALUATION seeds 0-2, with the protocol fixed beforehand on the MT10 development seeds (the
# defaults; docs/results/protocol-ablation-dev). 20 evaluation episodes per task after every phase,
# BC at every budget DAgger has a point at, then BC with balanced sampling (the second baseline of the
# MT10 study). Settings fixed on 2026-11-22, before any MT50 result. Run ONCE; resumable (finished
# runs are skipped, cut-off runs resumed). From the repository root:
#   nohup bash docs/results/mt50-state-eval/run.sh >> outputs/mt50-state-eval.log 2>&1 &
# Estimated cost on the 2-core machine: about 40 core-minutes per DAgger run and 4 per BC run,
# some 6 hours of wall time at --jobs=2.
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/mt50-state-eval
"$CLI" compare --methods='[bc,uniform,need,need_raw,gain]' --seeds='[0,1,2]' --jobs=2 \
  --output_dir="$OUT" --preset=metaworld-state --eval_episodes=20 --progress=false
"$CLI" compare --methods='[bc]' --seeds='[0,1,2]' --jobs=2 \
  --bc_budgets='[3,6,9,12,15,18,21,24,27,30,33]' --output_dir="$OUT-bc-balanced" \
  --preset=metaworld-state --eval_episodes=20 --progress=false --sampling=balanced
"$CLI" report --compare_dir="$OUT" --variants="{bc-balanced: $OUT-bc-balanced}" \
  --levels='[0.6,0.8,0.9]' --output_dir=docs/results/mt50-state-eval/report
