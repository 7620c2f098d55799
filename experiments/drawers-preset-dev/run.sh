#!/usr/bin/env bash
# The `drawers-pointcloud` preset's own training (development seeds 100-102): fixed steps, as the
# preset has them, or steps that grow with the data? Fixed 2026-11-27, before any of these runs.
#
# Why: the preset trains 1 500 steps at batch 64 per phase (12 passes over round 0's ~8 000 frames,
# under 2 over round 10's ~50 000). On the reduced drawer run, fixed steps made the DAgger rounds
# lower success and steps that grow with the data (12.4 passes) raised it (../visual-collapse-dev,
# section 7c); the BC grid showed the same (../drawer-placement-dev, run-epochs.sh). The preset's
# rounds are smaller (5 demos per drawer) and more (10), so that finding is checked here before the
# preset changes.
#
# Runs: `run --preset=drawers-pointcloud` (task need, 11 drawers, kitchen placement, 512 points,
# 10 + 10 x 5 demos per drawer, 5 evaluation episodes per training drawer and per unseen drawer after
# every phase), as the preset has it (`fixed`) and with `--training.steps_rule=epochs
# --training.epochs=12.4` (`epochs`), seeds 100, 101, 102; one run at a time on one core.
# Outcome and decision rule (fixed with the runs): per variant, the mean over seeds of the mean
# training-drawer success over phases 6-10 (5 phases x 55 episodes x 3 seeds). The preset switches to
# `epochs` if that mean is at least fixed's + 0.02 AND epochs' mean over those phases is not below its
# phase-0 mean (no decline with the rounds); otherwise it stays `fixed`, said so with the numbers.
# Reported beside, not deciding: every phase's mean, unseen-drawer success, wall time per run (the
# preset's one-hour target on the 2-core machine).
# Cost (estimate): fixed ~35 min a run (docs/benchmarks.md, "Whole visual preset runs"), epochs
# ~1.2-1.5 h (about 64 000 training steps in all); about 5.5 core-hours for the 6 runs.
# From a frozen worktree of the commit that added this file:
#   git worktree add --detach ../study-code-drawers-preset <commit>; cd ../study-code-drawers-preset
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   OMP_NUM_THREADS=1 PYTHONPATH=$PWD nohup taskset -c 0 bash docs/results/drawers-preset-dev/run.sh \
#     >> outputs/drawers-preset-dev.log 2>&1 &
# Resumable (run again after a stop); then `.venv/bin/python docs/results/drawers-preset-dev/table.py`.
set -euo pipefail
OUT=outputs/drawers-preset-dev
mkdir -p "$OUT"
run_preset() {  # run_preset VARIANT SEED [options...]
  local out="$OUT/$1-seed$2" resume=false
  shift 2
  [ -f "$out/policies/round-010/training.json" ] && return 0
  [ -d "$out" ] && resume=true
  echo "$(date -u +%H:%M:%S) start $out"
  .venv/bin/lerobot-mtdagger run --preset=drawers-pointcloud --rollout.workers=1 --progress=false \
    --seed="${out##*seed}" "$@" --output_dir="$out" --resume="$resume" > "$out.log" 2>&1
}
for SEED in 100 101 102; do
  run_preset fixed "$SEED"
  run_preset epochs "$SEED" --training.steps_rule=epochs --training.epochs=12.4
done
echo "$(date -u +%H:%M:%S) done"
