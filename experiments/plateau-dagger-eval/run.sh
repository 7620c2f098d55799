#!/usr/bin/env bash
# Evaluation seeds 0-4, MT10 state: need and uniform, each with the training ../plateau-dagger-training-dev
# chooses for it on the development seeds, against the best BC (cosine learning-rate decay,
# ../beyond-plateau-best-bc) past BC's plateau (#55 item 2). ../beyond-plateau-best-bc found need -
# best BC -0.014 [-0.040, +0.011] over 45-63 demos per task, but need ran with the plain training
# while BC's had been searched; this study gives need and uniform a training chosen the same way.
#
# Fixed on 2026-11-28, before any run of it and before ../plateau-dagger-training-dev has decided:
#   - each method's training: the decision of ../plateau-dagger-training-dev, whose table.py prints
#     `Decision: the best training of <method> is <training>.` per method (lab.bc_choice's rule). The
#     first run of this script runs that table.py on outputs/plateau-dagger-training-dev and writes
#     its output, once, to outputs/plateau-dagger-eval/decision.txt; it is never rewritten, and every
#     later run reads it. This script refuses to start (nothing is run, no decision.txt written) while either
#     method has no `Decision:` line or the development study's plain check (its last run) has not
#     finished: until then its decision is not final;
#   - the trainings' options: plain none; balanced --training.sampling=balanced; cosine
#     --training.lr_schedule=cosine; plateau --training.steps_rule=plateau (each phase of the method);
#   - a method whose chosen training is plain is not run: its evaluation-seed runs are
#     ../beyond-plateau-eval's (report/results.csv, the same settings; run from an older commit,
#     which the development study's plain check on seed 100 compares with today's code). If both
#     chose plain, nothing is run and the primary outcome is ../beyond-plateau-best-bc's secondary;
#   - everything else as ../beyond-plateau-eval and ../plateau-dagger-training-dev: the `small`
#     preset, 20 DAgger rounds (3 initial demos per task and 3 per task per round: 33 / 45 / 63 demos
#     per task after rounds 10 / 14 / 20), 20 evaluation episodes per task after every phase,
#     evaluation seeds 0-4; the best BC's runs are ../beyond-plateau-best-bc's (records/cosine/).
# Primary outcome (fixed by ../plateau-dagger-training-dev/run.sh; table.py): need(best training) -
# best BC in mean success over 45-63 demos per task (need: its 7 phases there, rounds 14-20; BC: its
# 45 and 63 budgets, as ../beyond-plateau-eval fixed the window), paired over the 5 seeds, 95% t
# interval. Read as: need ahead of the best BC if the interval is above 0, behind if below, no
# difference resolved otherwise. Secondary, on the same window: uniform(best) - best BC and
# need(best) - uniform(best). table.py also shows success per seed at 33, 45 and 63 demos per task.
# Every outcome waits for all 5 seeds: table.py prints "not finished" until then.
#
# Cost (../beyond-plateau-eval: a 20-round DAgger run takes about 20-25 min of one core): at most 10
# runs (2 methods x 5 seeds), about 4 core-hours at one job; 5 runs if one method chose plain.
# Runs: for each seed in SEEDS (default "0 1 2 3 4"), one compare per chosen non-plain training (both
# methods in one compare when they chose the same), into outputs/plateau-dagger-eval/<training>-seed<seed>.
# Two cores: one process per seed subset, e.g. SEEDS="0 1 2" on core 1 and SEEDS="3 4" on core 0 (they
# write different folders: a compare rewrites its folder's results.csv with its own runs only, so two
# processes never share one). Resumable: finished runs are skipped, cut-off ones resumed (compare).
# From a frozen worktree at the commit that added this file (experiments/resume.sh makes it):
#   PYTHONPATH=$PWD nohup bash experiments/plateau-dagger-eval/run.sh >> outputs/plateau-dagger-eval.log 2>&1 &
set -euo pipefail
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
PY=${PY:-.venv/bin/python}
OUT=${OUT:-outputs/plateau-dagger-eval}
DEV=${DEV:-outputs/plateau-dagger-training-dev}
HERE=$(dirname "$0")
log() { echo "$(date -u +%FT%H:%M:%S) $*"; }
py() { PYTHONPATH=experiments:${PYTHONPATH:-} "$PY" "$@"; }  # the table scripts import lab
mkdir -p "$OUT"
if [ ! -s "$OUT/decision.txt" ]; then
  tmp="$OUT/decision.tmp.$$"
  if ! py experiments/plateau-dagger-training-dev/table.py "$DEV" > "$tmp" \
    || ! py "$HERE/table.py" --trainings "$tmp" > /dev/null; then
    log "nothing run: finish ../plateau-dagger-training-dev first (its table.py on $DEV has not decided)"
    rm -f "$tmp"
    exit 1
  fi
  ln "$tmp" "$OUT/decision.txt" 2> /dev/null || true  # written once: never replaces an existing file
  rm -f "$tmp"
fi
trainings=$(py "$HERE/table.py" --trainings "$OUT/decision.txt")
log "chosen trainings ($OUT/decision.txt): $(echo "$trainings" | paste -sd ';')"
methods_of() { echo "$trainings" | sed -n "s/^\([a-z]*\): $1\$/\1/p" | paste -sd ,; }
if [ -z "$(methods_of balanced)$(methods_of cosine)$(methods_of plateau)" ]; then
  log "both methods chose plain: their runs are ../beyond-plateau-eval's; nothing to run"
  exit 0
fi
COMMON=(--jobs="${JOBS:-1}" --preset=small --dagger.rounds=20 --rollout.eval_episodes=20 --progress=false)
for seed in ${SEEDS:-0 1 2 3 4}; do
  for training in balanced cosine plateau; do
    methods=$(methods_of "$training")
    [ -n "$methods" ] || continue
    case "$training" in
      balanced) option=--training.sampling=balanced ;;
      cosine) option=--training.lr_schedule=cosine ;;
      plateau) option=--training.steps_rule=plateau ;;
    esac
    log "$training ($methods), seed $seed"
    "$CLI" compare --methods="[$methods]" --seeds="[$seed]" "${COMMON[@]}" "$option" \
      --output_dir="$OUT/$training-seed$seed"
  done
done
log "done"
