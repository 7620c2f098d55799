#!/usr/bin/env bash
# How far do two trainings on the very same drawer data differ, in-domain and on the unseen drawers?
# Development seeds; fixed 2026-11-27 before any of these runs.
#
# Why: on the evaluation seeds (../drawers-eval) the unseen-drawer differences between methods are
# wide (need - BC -0.088 [-0.408, +0.233]) and per unseen drawer success moved by up to 0.45 between
# trainings of one seed, whatever the method; each of those trainings also had other data. With
# `--training.seed` (the training draws alone: initial weights, batch order, task dropout) the data can
# be held fixed and the trainings repeated, so the spread between trainings is measured apart from the
# data's, before any claim about unseen drawers is made or planned.
#
# Runs: drawers-eval's BC at 20 demos per drawer, unchanged (`--preset=drawers-pointcloud`, kitchen
# placement, 512 points, `--training.steps_rule=epochs --training.epochs=12.4`, 20 evaluation episodes
# per training drawer and per unseen drawer), data seeds 100 and 101, training seeds 0-3 each: 8 runs,
# one at a time on one core. Within a data seed every run has the same frames (checked by table.py on
# the round files' checksums) and the same evaluation initial states.
# Outcomes (table.py): per data seed, the mean and the sample SD over the 4 trainings of the mean
# in-domain success (220 episodes) and of the mean unseen success (80 episodes); the SD pooled over the
# 2 data seeds (root of the mean variance); per unseen drawer, the range over the trainings.
# Rule for what follows (fixed with the runs): a study of unseen-drawer success that compares methods
# over S seeds needs K trainings per seed and method so that training alone moves a method's mean by a
# standard error of at most 0.03: K = ceil(pooled_SD^2 / (S x 0.03^2)), printed for S = 3 and S = 5;
# K = 1 (one training per run, as drawers-eval) is enough only where that gives 1.
# Cost (drawers-eval's BC runs on one core: 10-17 min each): about 1.5-2.3 core-hours.
# From a frozen worktree of the commit that added this file:
#   git worktree add --detach ../study-code-training-spread <commit>; cd ../study-code-training-spread
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   OMP_NUM_THREADS=1 PYTHONPATH=$PWD nohup taskset -c 0 bash docs/results/drawers-training-spread-dev/run.sh \
#     >> outputs/drawers-training-spread-dev.log 2>&1 &
# Resumable (run again after a stop); then, from ../main,
#   bash docs/results/drawers-training-spread-dev/save_records.sh
#   .venv/bin/python docs/results/drawers-training-spread-dev/table.py > docs/results/drawers-training-spread-dev/table.txt
set -euo pipefail
OUT=outputs/drawers-training-spread-dev
mkdir -p "$OUT"
for SEED in 100 101; do
  for TRAINING_SEED in 0 1 2 3; do
    RUN="$OUT/bc20-seed$SEED-train$TRAINING_SEED"
    [ -f "$RUN/policies/round-000/training.json" ] && continue
    RESUME=false
    [ -d "$RUN" ] && RESUME=true
    echo "$(date -u +%H:%M:%S) start $RUN"
    .venv/bin/lerobot-mtdagger run --preset=drawers-pointcloud --mode=bc --dagger.rounds=1 \
      --dagger.budget_per_task=10 --training.steps_rule=epochs --training.epochs=12.4 \
      --rollout.eval_episodes=20 --rollout.workers=1 --progress=false --seed="$SEED" \
      --training.seed="$TRAINING_SEED" --output_dir="$RUN" --resume="$RESUME" > "$RUN.log" 2>&1
  done
done
echo "$(date -u +%H:%M:%S) done"
