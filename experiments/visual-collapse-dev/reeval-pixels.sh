#!/usr/bin/env bash
# MT10 pixels: every saved phase policy of the pixel runs evaluated again, 20 episodes per task
# (200 per policy), so that a DAgger round's change of 0.05 can be told from noise (the runs' own
# evaluation used 5 per task). Fixed before any of these evaluations ran:
#   - policies: outputs/visual-dev/{pixels,pixels-balanced}-seed{100,101,102}/policies/round-00{0,1,2}
#     (each one that exists; the script is rerun as runs finish and skips what is done);
#   - 20 episodes per task, evaluation seed 9000 for every policy (the same initial states for every
#     phase and run: differences are paired episode by episode), no env worker process (--workers=0);
#   - primary outcome: the change of mean success from phase 0 (BC) to phase 2, paired over seeds
#     100-102 (95% t interval), for uniform sampling (`pixels`); the same for phase 1 and for
#     `pixels-balanced` as secondary (reeval_summary.py prints them).
# From a frozen worktree at a4bae9a (the first commit whose `eval` takes image policies):
#   git worktree add --detach ../study-code-reeval a4bae9a; cd ../study-code-reeval
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   JOBS=2 nohup bash ../main/docs/results/visual-collapse-dev/reeval-pixels.sh >> outputs/reeval-pixels.log 2>&1 &
# (A second instance with REVERSE=1 takes the list from its end, beside a first one; an evaluation in
# progress leaves NAME.json.partial, which both skip: delete stale .partial files after a kill.)
set -euo pipefail
OUT=outputs/visual-dev/reeval
mkdir -p "$OUT"
evaluate() {
  local policy=$1
  local run round target
  run=$(basename "$(dirname "$(dirname "$policy")")")
  round=$(basename "$policy")
  target="$OUT/$run-$round.json"
  [ -f "$target" ] && return 0
  [ -f "$target.partial" ] && return 0  # being evaluated by another instance (delete stale ones first)
  echo "$(date -u +%H:%M:%S) start $run $round"
  touch "$target.partial"  # marks the evaluation as in progress (eval writes the file only at its end)
  PYTHONPATH=$PWD OMP_NUM_THREADS=1 MUJOCO_GL=egl .venv/bin/python -m lerobot_mtdagger.cli eval --policy_path="$policy" \
    --suite.name=metaworld-mt10 --episodes=20 --seed=9000 --workers=0 --output="$target.partial" > /dev/null \
    && mv "$target.partial" "$target" && echo "$(date -u +%H:%M:%S) done $run $round" \
    || echo "$(date -u +%H:%M:%S) FAILED $run $round"
}
export -f evaluate
export OUT
# The primary outcome's policies (uniform sampling) first, then balanced sampling's.
for name in pixels pixels-balanced; do
  ls -d outputs/visual-dev/$name-seed10{0,1,2}/policies/round-00{0,1,2} 2>/dev/null || true
done | if [ -n "${REVERSE:-}" ]; then tac; else cat; fi | xargs -P "${JOBS:-1}" -I{} bash -c 'evaluate {}'
