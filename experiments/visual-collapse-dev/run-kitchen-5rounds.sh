#!/usr/bin/env bash
# The kitchen runs (run-kitchen.sh) extended from 2 to 5 DAgger rounds of 10 demos per drawer (beta 0
# from round 2 on, as before: beta starts at 1 and loses 0.5 a round), 10 -> 60 demos per drawer:
# do later rounds lower the point-cloud student's success under the kitchen placement? This is also
# the development pilot of the drawer evaluation-seed study's DAgger protocol. Fixed 2026-11-26, after
# phase 0 of seed 100 only had been seen. Same frozen worktree as run-kitchen.sh (a4d22ce); resumes
# each run from its last committed round (phases 0-2 are kept as they are):
#   cd ../study-code-kitchen
#   OMP_NUM_THREADS=1 nohup bash ../main/docs/results/visual-collapse-dev/run-kitchen-5rounds.sh >> outputs/kitchen-dev.log 2>&1 &
set -euo pipefail
for SEED in ${SEEDS:-100 101 102}; do
  PYTHONPATH=$PWD .venv/bin/lerobot-mtdagger run --suite.name=drawers --suite.obs_mode=pointcloud \
    --scheduler.type=need --dagger.initial_demos=10 --dagger.budget_per_task=10 --dagger.rounds=5 \
    --training.steps_per_round=1500 --policy.batch_size=64 --suite.num_points=512 \
    --rollout.eval_episodes=5 --scheduler.n_min=2 --rollout.workers=1 --seed="$SEED" --progress=false \
    --output_dir="outputs/visual-dev/kitchen-seed$SEED" --resume=true
done
