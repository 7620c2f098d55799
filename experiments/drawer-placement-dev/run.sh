#!/usr/bin/env bash
# Do the kitchen placement ranges make the drawers need perception? Point-cloud BC (round 0 only)
# at 10, 30 and 60 expert demos per drawer under the old ("narrow") and the new ("kitchen")
# placement, development seed 100 only. Same protocol as the visual-collapse study's reduced run
# (512 points, 1 500 steps at batch 64, 5 evaluation episodes per drawer plus the 4 unseen drawers),
# so narrow at 10 demos is also that study's phase 0. Runs from a frozen worktree:
#   git worktree add --detach ../study-code-placement <commit>; cd ../study-code-placement
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   bash ../main/docs/results/drawer-placement-dev/run.sh PLACEMENT DEMOS SEED
set -euo pipefail
PLACEMENT=$1
DEMOS=$2
SEED=$3
OUT="outputs/placement-dev/bc-$PLACEMENT-${DEMOS}demos-seed$SEED"
RESUME=false
[ -d "$OUT" ] && RESUME=true
.venv/bin/lerobot-mtdagger run --suite=drawers --obs_mode=pointcloud --placement="$PLACEMENT" \
  --initial_demos="$DEMOS" --rounds=0 --steps_per_round=1500 --policy.batch_size=64 \
  --num_points=512 --eval_episodes=5 --seed="$SEED" --progress=false --workers=1 \
  --output_dir="$OUT" --resume="$RESUME"
