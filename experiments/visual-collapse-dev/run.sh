#!/usr/bin/env bash
# Why visual DAgger made the point-cloud drawer student worse (development seeds 100-102 only).
# The reduced run, unchanged: 11 drawers, 512 points, 10 demos per drawer in round 0, 2
# DAgger rounds of 10 per drawer (beta 0.5 then 0), 1 500 warm-started steps per phase at batch 64,
# 5 evaluation episodes per drawer. Runs from a frozen worktree (as the other studies):
#   git worktree add --detach ../study-code-visual <commit>; cd ../study-code-visual
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   PYTHONPATH=/work/main/docs/results/mt10-state-eval/frozen-code:$PWD bash ../main/docs/results/visual-collapse-dev/run.sh NAME SEED [EXTRA ARGS]
# NAME names the run (outputs/visual-dev/NAME-seedSEED); EXTRA ARGS are the variant's options.
set -euo pipefail
NAME=$1
SEED=$2
shift 2
OUT="outputs/visual-dev/$NAME-seed$SEED"
RESUME=false
[ -d "$OUT" ] && RESUME=true
.venv/bin/lerobot-mtdagger run --suite=drawers --obs_mode=pointcloud --scheduler.type=need \
  --initial_demos=10 --budget_per_task=10 --rounds=2 --steps_per_round=1500 --policy.batch_size=64 \
  --num_points=512 --eval_episodes=5 --scheduler.n_min=2 --seed="$SEED" --progress=false \
  --output_dir="$OUT" "$@" --resume="$RESUME"
