#!/usr/bin/env bash
# The compare line of run.sh with --seeds='[2,3,4]' only: outputs/ with seeds 0-1 was lost between
# sessions, and seeds 0 and 1 are saved in seeds/ (README "If outputs/ is lost"). Every other setting
# is run.sh's, unchanged. Run from the frozen worktree at c1f23fb (README), resumable:
# (JOBS=1 OMP_NUM_THREADS=1 runs it on one core beside other work; the job count changes no setting.)
#   PYTHONPATH=$SHIM:$PWD nohup bash ../main/docs/results/beyond-plateau-eval/run-seeds-2-4.sh >> outputs/beyond-plateau-eval.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/beyond-plateau-eval
"$CLI" compare --methods='[need,bc,uniform]' --seeds='[2,3,4]' --jobs="${JOBS:-2}" --preset=small --rounds=20 \
  --bc_budgets='[12,21,33,45,63]' --eval_episodes=20 --progress=false --output_dir="$OUT"
"$CLI" report --compare_dir="$OUT" --levels='[0.8,0.9,0.95]' --output_dir="$OUT/report"
