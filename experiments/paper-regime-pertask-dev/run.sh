#!/usr/bin/env bash
# The paper's regime on MetaWorld state, second attempt: with a noise scale PER TASK, do MT50's experts
# succeed 0.80-0.95 and does BC stop saturating? DEVELOPMENT seeds only; fixed 2026-11-28, before any run.
#
# Why: ../paper-regime-calibration-dev found that one noise scale splits MT50 (buttons and doors stay
# above 0.95 while grasping and insertion fall under 0.80) and at its fallback (0.2, 31 easy tasks) BC
# still reached 0.883 at 18 demos per task. `--expert.noise_by_task` (added for this) gives each task
# its own scale, so every task can sit in the band, the hard ones included.
#
# Step 1 (calibrate.py noise, the rule): each MT50 task's scale from the committed sweep
# (../paper-regime-calibration-dev/records/expert-success.json: scales 0, 0.1, 0.2, 0.3, 0.45, 0.6,
# correlation 0.9, noise seed 100, reset seeds 1000-1019): among the scales whose success lies in
# [0.80, 0.95], the one nearest 0.875 (ties: the larger). None in band: above 0.95 at every scale -> 0.6
# (the largest measured; not raised further); else bisect between the largest scale above 0.95 and the
# first under 0.80, at most twice, on the sweep's episodes, taking the first midpoint in band, else the
# largest measured scale at or above 0.80. Under 0.80 without noise -> 0 (the task is then dropped).
# Step 2 (a fresh check, no selection bias): benchmarks/expert_success.py with that map on OTHER reset
# seeds (2000-2019), 20 episodes per task; kept tasks K: success >= 0.80 there (the paper's rule).
# Reported: |K|, their mean, how many in [0.80, 0.95].
# Step 3 (BC check on K with their scales): `compare --methods='[bc]'`, `--preset=metaworld-state`, BC
# budgets 6 and 18 demos per task, seeds 100 and 101, 20 evaluation episodes per task, labels = the
# executed noisy actions (`--expert.labels=noisy`), noise correlation 0.9, noise seed 100.
# The regime is ACCEPTED if BC's mean success at 18 demos per task over the two seeds is below 0.80
# (over 3x the 5.4 demos BC needs to reach 80% with perfect experts). If it is not, this is said with the
# numbers and nothing else is tried here: the next attempt is a study of its own, fixed before its runs.
# If accepted, the training search (issue item 5) and the comparison on evaluation seeds (item 6) are
# the next studies, each fixed before its runs.
#
# Cost (estimated before any run, on ONE core, core 0): step 1 about 25 bisected tasks x 2 x 20 episodes,
# ~5 min; step 2 ~0.5 M env steps, ~8 min; step 3 four BC runs, 10-20 min each: about 1-1.3 h.
# From a frozen worktree of the commit that added this file (experiments/resume.sh makes it):
#   PYTHONPATH=$PWD nohup bash experiments/paper-regime-pertask-dev/run.sh >> outputs/paper-regime-pertask-dev.log 2>&1 &
# Resumable: a finished step is skipped, and compare resumes its runs.
set -euo pipefail
HERE=$(dirname "$0")
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
PY=${PY:-.venv/bin/python}
OUT=outputs/paper-regime-pertask-dev
SWEEP=experiments/paper-regime-calibration-dev/records/expert-success.json
mkdir -p "$OUT"
log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

if [ ! -s "$OUT/noise-by-task.json" ]; then
  log "step 1: each task's noise scale"
  "$PY" "$HERE/calibrate.py" noise "$OUT" "$SWEEP"
fi
if [ ! -s "$OUT/check.json" ]; then
  log "step 2: the fresh check of the experts at their scales"
  "$PY" benchmarks/expert_success.py --suite metaworld-mt50 --noise 0 --noise-by-task "$OUT/noise-by-task.json" \
    --correlation 0.9 --noise-seed 100 --episodes 20 --first-seed 2000 --jobs 1 \
    --json "$OUT/check.tmp.json" > "$OUT/check.md"
  mv "$OUT/check.tmp.json" "$OUT/check.json"
fi
"$PY" "$HERE/calibrate.py" kept "$OUT" > "$OUT/kept.txt"
tasks=$(sed -n 's/^tasks: //p' "$OUT/kept.txt")
map=$(sed -n 's/^map: //p' "$OUT/kept.txt")
log "step 3: BC on $(tr ',' '\n' <<< "$tasks" | wc -l) kept tasks"
"$CLI" compare --methods='[bc]' --seeds='[100,101]' --bc_budgets='[6,18]' --jobs="${JOBS:-1}" \
  --output_dir="$OUT/bc" --preset=metaworld-state --suite.tasks="[$tasks]" \
  --rollout.eval_episodes=20 --expert.noise_by_task="$map" --expert.noise_correlation=0.9 \
  --expert.noise_seed=100 --expert.labels=noisy --progress=false
if "$PY" "$HERE/calibrate.py" bc "$OUT" > "$OUT/bc-check.txt"; then
  log "accepted ($OUT/bc-check.txt)"
else
  log "not accepted ($OUT/bc-check.txt)"
fi
log "done"
