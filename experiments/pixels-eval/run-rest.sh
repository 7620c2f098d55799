#!/usr/bin/env bash
# run.sh's compare line with BC seed 0 left out: outputs/ was lost between sessions (a new checkout,
# 2026-11-27 12:00 UTC) after BC seed 0 had finished at all six budgets, and those six runs are saved
# in records/ (config, round records, training records with their evaluations). Every other run of
# run.sh's plan is here, with run.sh's settings unchanged: uniform, need and gain on seed 0 (all three
# were cut or not started), then every method on seeds 1 and 2. The table and report are drawn from
# records/ once every run has finished (`report --records`, README "Tabulation"), not by this script.
# Run from the frozen worktree at f33425a (README), one process per core, resumable; two processes
# share the plan (each skips the finished runs; a run the other holds fails at once and is left to it):
#   cd ../study-code-pixels-eval && PYTHONPATH=$PWD JOBS=1 taskset -c 0 \
#     bash ../main/docs/results/pixels-eval/run-rest.sh >> outputs/pixels-eval-core0.log 2>&1
set -uo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/pixels-eval
DECISION=$(sed -n 's/^Decision: BC samples \([a-z]*\).*/\1/p' docs/results/pixels-bc-dev/table.txt)
if [ "$DECISION" != balanced ]; then
  echo "docs/results/pixels-bc-dev/table.txt must say 'Decision: BC samples balanced' (copy it from ../main)." >&2
  exit 1
fi
COMMON=(--jobs="${JOBS:-2}" --preset=metaworld-pixels --rollout.eval_episodes=20 --progress=false
  --training.sampling=balanced --output_dir="$OUT")
status=0
"$CLI" compare --methods='[uniform,need,gain]' --seeds='[0]' "${COMMON[@]}" || status=1
"$CLI" compare --methods='[bc,uniform,need,gain]' --seeds='[1,2]' "${COMMON[@]}" || status=1
exit "$status"
