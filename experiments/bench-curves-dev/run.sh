#!/usr/bin/env bash
# The replay bench's development curves past 30 demos per task (issue "When does scheduling pay?",
# item 2: the curves must cover the demos a scheduler may give a task; task need gave hard tasks up
# to 60 demos per task in the paper-regime study, where BC was measured only to 30).
# DEVELOPMENT seeds only (100, 101), fixed 2026-12-04 before any run. Not a comparison: no outcome,
# no verdict; these runs only extend the curves of ../paper-regime-training-dev (cosine BC at 6, 18
# and 30 demos per task, and every DAgger run's round 0 at 3) to 45 and 60 demos per task.
#
# Setting: ../paper-regime-training-dev's, unchanged (the imperfect-expert MT50 of
# ../paper-regime-pertask-dev: its kept.txt tasks and noise map, correlation 0.9, noise seed 100,
# noisy labels; --preset=metaworld-state; cosine learning rate, BC trained as long as the DAgger
# policy at the same budget; 10 evaluation episodes per task). Arm: bc at 45 and 60 demos per task.
# Cost: measured on the first run (BC at 30 there: about 14 min of one core); expected about 20-30
# min per run, 4 runs; SEEDS=100 and SEEDS=101 run on one core each. Resumable: `compare` skips
# finished runs.
# From a frozen worktree of the code (the run code is that of 738e42a):
#   git worktree add --detach ../study-bench 738e42a
#   cd ../study-bench && nohup bash ../main/experiments/bench-curves-dev/run.sh > ../main/outputs/bench-curves-dev.log 2>&1 &
set -euo pipefail
CLI=${CLI:-/work/main/.venv/bin/lerobot-mtdagger}
OUT=${OUT:-/work/main/outputs/bench-curves-dev}
KEPT=/work/main/experiments/paper-regime-pertask-dev/records/kept.txt
log() { echo "$(date -u +%FT%H:%M:%S) $*"; }
tasks=$(sed -n 's/^tasks: //p' "$KEPT")
map=$(sed -n 's/^map: //p' "$KEPT")
SETTING=(--methods='[bc]' --bc_budgets='[45,60]' --jobs=1 --preset=metaworld-state
  --dagger.rounds=9 --suite.tasks="[$tasks]" --expert.noise_by_task="$map" --expert.noise_correlation=0.9
  --expert.noise_seed=100 --expert.labels=noisy --rollout.eval_episodes=10 --progress=false
  --training.lr_schedule=cosine)
for seed in ${SEEDS:-100 101}; do
  log "cosine BC at 45 and 60 demos per task, seed $seed"
  "$CLI" compare "${SETTING[@]}" --seeds="[$seed]" --output_dir="$OUT/cosine-seed$seed"
done
log "done"
