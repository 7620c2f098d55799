#!/usr/bin/env bash
# run.sh's plan, less every run that records/ or outputs/ already holds to its last phase: for a
# restart on a checkout that has lost outputs/ (run-rest.sh would run again every run not in
# outputs/, records or not). No setting differs from run.sh: each missing run is one `compare` call
# for its method, seed (and BC budget) with run.sh's options, so its command is the one run.sh's
# compare gives it. Runs in the order run.sh's compare plans them. Written 2026-11-27 17:40 UTC,
# scheduling only. From the frozen worktree, one process per core (a run the other process holds is
# refused at once by its lock; that call fails and this process goes on to the next run):
#   cd ../study-code-pixels-eval && JOBS=1 PYTHONPATH=$PWD taskset -c 0 \
#     bash ../main/docs/results/pixels-eval/run-missing.sh
# CLI=echo prints the calls instead of running them.
set -uo pipefail
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
OUT=outputs/pixels-eval
RECORDS=${RECORDS:-../main/docs/results/pixels-eval/records}
DECISION=$(sed -n 's/^Decision: BC samples \([a-z]*\).*/\1/p' docs/results/pixels-bc-dev/table.txt)
if [ "$DECISION" != balanced ]; then
  echo "docs/results/pixels-bc-dev/table.txt must say 'Decision: BC samples balanced' (copy it from ../main)." >&2
  exit 1
fi
COMMON=(--jobs="${JOBS:-2}" --preset=metaworld-pixels --rollout.eval_episodes=20 --progress=false
  --training.sampling=balanced --output_dir="$OUT")

held() {  # held NAME LAST_PHASE: records/ or outputs/ hold the run's phase LAST_PHASE (its last)
  local phase
  phase=$(printf 'round-%03d' "$2")
  [ -f "$RECORDS/$1/policies/$phase/training.json" ] || [ -f "$OUT/runs/$1/policies/$phase/training.json" ]
}

status=0
for SEED in 0 1 2; do
  for BUDGET in 10 20 30 40 50 60; do
    held "bc-${BUDGET}demos-seed$SEED" 0 && continue
    "$CLI" compare --methods='[bc]' --bc_budgets="[$BUDGET]" --seeds="[$SEED]" "${COMMON[@]}" || status=1
  done
  for METHOD in uniform need gain; do
    held "$METHOD-seed$SEED" 5 && continue
    "$CLI" compare --methods="[$METHOD]" --seeds="[$SEED]" "${COMMON[@]}" || status=1
  done
done
exit "$status"
