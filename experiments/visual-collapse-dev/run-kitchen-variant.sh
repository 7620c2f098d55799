#!/usr/bin/env bash
# Under the kitchen placement the two DAgger rounds lowered mean success (run-kitchen.sh, seeds
# 100-102: 0.897 -> 0.855 -> 0.849). Two variants of the same runs, chosen after seeing that and
# before any variant run (2026-11-26), each on seeds 100-102:
#   balanced: --training.sampling=balanced (each drawer an equal share of every batch; what stopped
#             the MT10 pixel rounds from lowering success, section 6c);
#   epochs:   --training.steps_rule=epochs --training.epochs=12.4 (every phase 12.4 passes over all
#             its rounds' frames, warm-started: round 0's compute per frame kept as the data grow,
#             about 1 500 / 3 300 / 5 400 steps instead of 1 500 each).
# A variant keeps the criterion if its mean success over the 3 seeds at phases 1 and 2 is not
# below its phase 0 (5 episodes per drawer, as the other runs here; noisy: about +-0.05 per mean).
# Usage, from the kitchen runs' frozen worktree (../study-code-kitchen at a4d22ce):
#   OMP_NUM_THREADS=1 bash ../main/docs/results/visual-collapse-dev/run-kitchen-variant.sh balanced 100 --training.sampling=balanced
#   OMP_NUM_THREADS=1 bash ../main/docs/results/visual-collapse-dev/run-kitchen-variant.sh epochs 100 --training.steps_rule=epochs --training.epochs=12.4
# Resumable: run the same line again after a stop.
set -euo pipefail
NAME=$1
SEED=$2
shift 2
OUT="outputs/visual-dev/kitchen-$NAME-seed$SEED"
RESUME=false
[ -d "$OUT" ] && RESUME=true
PYTHONPATH=$PWD .venv/bin/lerobot-mtdagger run --suite.name=drawers --suite.obs_mode=pointcloud \
  --scheduler.type=need --dagger.initial_demos=10 --dagger.budget_per_task=10 --dagger.rounds=2 \
  --training.steps_per_round=1500 --policy.batch_size=64 --suite.num_points=512 \
  --rollout.eval_episodes=5 --scheduler.n_min=2 --rollout.workers=1 --seed="$SEED" --progress=false \
  --output_dir="$OUT" "$@" --resume="$RESUME"
