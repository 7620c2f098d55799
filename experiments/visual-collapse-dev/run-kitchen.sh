#!/usr/bin/env bash
# The hold runs (section 5) again under the drawers' default placement, `kitchen` (+-10 cm across,
# +-5 cm deep, +-12 degrees, 0-6 cm higher, colours +-0.2), which became the default after them:
# does a DAgger round lower the point-cloud student's success where the drawers must be read?
# The same reduced run as run.sh, spelt with the grouped options of a4d22ce, seeds 100, 101 and 102 one after the other on one core, from a
# frozen worktree at a4d22ce (fixed 2026-11-26 before any kitchen DAgger run):
#   git worktree add --detach ../study-code-kitchen a4d22ce; cd ../study-code-kitchen
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   OMP_NUM_THREADS=1 nohup bash ../main/docs/results/visual-collapse-dev/run-kitchen.sh >> outputs/kitchen-dev.log 2>&1 &
# Resumable: run again after a stop. Tables: rounds_summary.py outputs/visual-dev/kitchen-seedSEED.
set -euo pipefail
for SEED in 100 101 102; do
  OUT="outputs/visual-dev/kitchen-seed$SEED"
  RESUME=false
  [ -d "$OUT" ] && RESUME=true
  PYTHONPATH=$PWD .venv/bin/lerobot-mtdagger run --suite.name=drawers --suite.obs_mode=pointcloud \
    --scheduler.type=need --dagger.initial_demos=10 --dagger.budget_per_task=10 --dagger.rounds=2 \
    --training.steps_per_round=1500 --policy.batch_size=64 --suite.num_points=512 \
    --rollout.eval_episodes=5 --scheduler.n_min=2 --rollout.workers=1 --seed="$SEED" --progress=false \
    --output_dir="$OUT" --resume="$RESUME"
done
