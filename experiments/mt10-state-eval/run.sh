#!/usr/bin/env bash
# MetaWorld MT10 state on the EVALUATION seeds 0-4, with the protocol fixed beforehand on the
# development seeds (docs/results/protocol-ablation-dev): the defaults. 20 evaluation episodes per
# task after every phase, 6 DAgger rounds of 3 demos per task after 3 initial demos per task (up to
# 21 per task), BC at every budget DAgger has a point at. Run ONCE; resumable (finished runs are
# skipped, cut-off runs resumed). From the repository root:
#   nohup bash docs/results/mt10-state-eval/run.sh > outputs/mt10-state-eval.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/mt10-state-eval
"$CLI" compare --methods='[bc,uniform,need,need_raw,gain]' --seeds='[0,1,2,3,4]' --jobs=2 \
  --output_dir="$OUT" --preset=small --rounds=6 --eval_episodes=20 --progress=false
"$CLI" report --compare_dir="$OUT" --levels='[0.6,0.8,0.9]'
# The second BC baseline: BC's best training variant on the development seeds (balanced sampling).
"$CLI" compare --methods='[bc]' --seeds='[0,1,2,3,4]' --jobs=2 --bc_budgets='[3,6,9,12,15,18,21]' \
  --output_dir="$OUT-bc-balanced" --preset=small --rounds=6 --eval_episodes=20 --progress=false \
  --sampling=balanced
"$CLI" report --compare_dir="$OUT-bc-balanced" --levels='[0.6,0.8,0.9]'
