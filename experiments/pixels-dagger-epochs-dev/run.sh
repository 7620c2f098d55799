#!/usr/bin/env bash
# Do the pixel DAgger rounds lose the hard tasks because 1 500 fixed steps per phase under-train them?
# Development seeds 100-102; fixed 2026-11-27 20:15 UTC, before any of these runs.
#
# Why: on the evaluation seeds (../pixels-eval) every DAgger method ends at 0.67-0.70 while BC reaches
# 0.80 at 60 demos per task; push, pick-place and peg-insert-side fall to 0-0.05 under DAgger (from
# 0.07-0.12 at 10 demos) and reach 0.40-0.53 under BC. `--preset=metaworld-pixels` warm-starts 1 500
# steps per phase whatever the data: at phase 5 that is 0.6-0.8 passes over 115 000-154 000 frames,
# where BC at 60 demos takes 10.3 passes over 55 800. On the drawers, steps that grow with the data
# turned the same decline into a gain (../visual-collapse-dev 7c).
#
# Runs: `compare --methods='[uniform]'` with `--preset=metaworld-pixels` (84 px RGB, 10 demos per task,
# 5 DAgger rounds of 10, batches balanced over tasks), 20 evaluation episodes per task after every
# phase, seeds 100, 101, 102, in two arms: `epochs` (`--training.steps_rule=epochs
# --training.epochs=10`: 10 passes over each phase's frames, about BC's 10.3-11.3) first, then
# `fixed` (the preset as it is). Uniform only: on the evaluation seeds the schedulers are level with
# it (need - uniform -0.002 [-0.008, +0.003]), and the question is the training, not the schedule.
# Outcomes (table.py), paired over the 3 seeds, 95% t interval:
#   primary: epochs - fixed in mean success at phase 5 (60 demos per task);
#   secondary: the same on push, pick-place and peg-insert-side (mean of the three); epochs and fixed
#   at phase 5 against ../pixels-bc-dev's balanced BC at 60 demos (same seeds, same evaluation);
#   every phase's mean; wall time per run.
# Rule (fixed with the runs): the preset's DAgger phases switch to `epochs` (10 passes) if epochs -
# fixed at phase 5 is at least +0.03 in mean over seeds AND epochs' phase 5 is not below its phase 0
# in mean; otherwise the preset stays `fixed`, said so with the numbers. A rerun of ../pixels-eval's
# DAgger methods with the switched preset is proposed only if epochs' phase 5 is also within 0.02 of
# balanced BC at 60 demos (or above it) in mean.
# Cost (estimate, one core): fixed ~55-75 min a run (../pixels-eval); epochs adds about 35-40 min of
# training (about 3.6 M samples at ~1 450 samples/s) for ~95-115 min a run: about 8-9 core-hours for
# the 6 runs. Memory: a pixel DAgger run peaks at 7-10 GB PSS (../pixels-eval).
# From a frozen worktree of the commit that added this file:
#   git worktree add --detach ../study-code-pixels-epochs <commit>; cd ../study-code-pixels-epochs
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   OMP_NUM_THREADS=1 PYTHONPATH=$PWD nohup taskset -c 1 bash docs/results/pixels-dagger-epochs-dev/run.sh \
#     >> outputs/pixels-dagger-epochs-dev.log 2>&1 &
# Resumable (run again after a stop); then, from ../main, save_records.sh and table.py (its header).
set -euo pipefail
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
OUT=outputs/pixels-dagger-epochs-dev
COMMON=(--methods='[uniform]' --seeds='[100,101,102]' --jobs=1 --preset=metaworld-pixels
  --rollout.eval_episodes=20 --progress=false)
"$CLI" compare "${COMMON[@]}" --training.steps_rule=epochs --training.epochs=10 --output_dir="$OUT/epochs"
"$CLI" compare "${COMMON[@]}" --output_dir="$OUT/fixed"
echo "$(date -u +%H:%M:%S) done"
