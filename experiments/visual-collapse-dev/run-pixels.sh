#!/usr/bin/env bash
# MT10 pixels: does a DAgger round lower the RGB student's success? (development seeds 100-102 only)
# The drawer check's reduced run (run.sh) on MetaWorld MT10 with 84 px RGB: 10 demos per task in
# round 0, 2 DAgger rounds of 10 per task (beta 0.5 then 0), 1 500 warm-started steps per phase at
# batch 64, 5 evaluation episodes per task, need scheduler. From a frozen worktree (868b86d):
#   git worktree add --detach ../study-code-pixels 868b86d; cd ../study-code-pixels
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   OMP_NUM_THREADS=1 nohup nice -n 10 bash ../main/docs/results/visual-collapse-dev/run-pixels.sh SEED >> outputs/pixels-dev.log 2>&1 &
# A variant: NAME=pixels-balanced ... run-pixels.sh SEED --sampling=balanced (written to outputs/visual-dev/NAME-seedSEED).
set -euo pipefail
SEED=$1
shift
OUT="outputs/visual-dev/${NAME:-pixels}-seed$SEED"
RESUME=false
[ -d "$OUT" ] && RESUME=true
.venv/bin/lerobot-mtdagger run --suite=metaworld-mt10 --obs_mode=rgb --scheduler.type=need \
  --initial_demos=10 --budget_per_task=10 --rounds=2 --steps_per_round=1500 --policy.batch_size=64 \
  --eval_episodes=5 --scheduler.n_min=2 --workers=1 --seed="$SEED" --progress=false \
  --output_dir="$OUT" "$@" --resume="$RESUME"
