#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the #31 studies still running, one process pinned to each core of
# the 2-core machine (`taskset`: docs/benchmarks.md, "Threads per run"), every step resumable. Works on
# a new checkout (no outputs/, no worktrees): it makes the frozen worktrees it needs. From ../main,
# once the README's setup command has made .venv, from a copy (bash reads a script as it runs it, so
# editing this file would change a running one):
#   mkdir -p outputs && cp docs/results/resume.sh outputs/resume-running.sh
#   nohup bash outputs/resume-running.sh >> outputs/resume.log 2>&1 &
#
# Both cores (unless run-rest.sh or run-missing.sh processes are already running: then it waits for
#   them to end): pixels-eval's run-missing.sh (run.sh's plan less every run records/ or outputs/
#   holds finished), one process each from ../study-code-pixels-eval (f33425a), sharing the plan; each
#   skips finished runs and leaves a run the other holds to it. (Until 2026-11-27 17:45 UTC:
#   run-rest.sh, which reruns every run not in outputs/ but BC seed 0.) Once both are done: the
#   records, the report drawn from them (`report --records`) and table.txt, here.
# Then core 1: drawers-preset-dev (../study-code-drawers-preset at e52ef80); core 0:
#   drawers-training-spread-dev (../study-code-training-spread at a5a8d2f), then its records and table.
# (Until 2026-11-27 12:00 UTC this script ran queue.sh's two lanes: bc-past-plateau-dev and
# beyond-plateau-best-bc, pixels-bc-dev, then pixels-eval; all but pixels-eval are complete.)
set -uo pipefail

log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

worktree() {  # worktree NAME COMMIT: ../NAME frozen at COMMIT, with this checkout's .venv and outputs/
  if [ ! -d "../$1" ]; then
    git worktree prune
    git worktree add --detach "../$1" "$2" || return 1
  fi
  ln -sf ../main/.venv "../$1/.venv"
  ln -sfn ../main/outputs "../$1/outputs"
}

PIXELS=../study-code-pixels-eval

pixels_rest() {  # pixels_rest CORE: one run-missing.sh process pinned to CORE
  (cd "$PIXELS" && JOBS=1 PYTHONPATH=$PWD taskset -c "$1" \
    bash ../main/docs/results/pixels-eval/run-missing.sh) >> "outputs/pixels-eval-core$1.log" 2>&1
}

pixels_tabulate() {  # the records, the report from them and the table fixed in run.sh
  bash docs/results/pixels-eval/save_records.sh
  .venv/bin/lerobot-mtdagger report --records='[docs/results/pixels-eval/records]' --levels='[0.6,0.7]' \
    --output_dir=docs/results/pixels-eval/report > outputs/pixels-eval-report.log 2>&1 || return 1
  .venv/bin/python docs/results/pixels-eval/table.py docs/results/pixels-eval/report/results.csv \
    > docs/results/pixels-eval/table.txt
}

training_spread() {  # drawers-training-spread-dev on CORE, then its records and table
  (cd ../study-code-training-spread && OMP_NUM_THREADS=1 PYTHONPATH=$PWD taskset -c "$1" \
    bash docs/results/drawers-training-spread-dev/run.sh) >> outputs/drawers-training-spread-dev.log 2>&1 \
    || return 1
  bash docs/results/drawers-training-spread-dev/save_records.sh
  .venv/bin/python docs/results/drawers-training-spread-dev/table.py \
    > docs/results/drawers-training-spread-dev/table.txt
}

drawers_preset() {  # drawers-preset-dev, one run at a time on CORE
  (cd ../study-code-drawers-preset && OMP_NUM_THREADS=1 PYTHONPATH=$PWD taskset -c "$1" \
    bash docs/results/drawers-preset-dev/run.sh) >> outputs/drawers-preset-dev.log 2>&1
}

mkdir -p outputs
worktree study-code-pixels-eval f33425a || { log "cannot make $PIXELS"; exit 1; }
cp docs/results/pixels-bc-dev/table.txt "$PIXELS/docs/results/pixels-bc-dev/table.txt"  # the decision
worktree study-code-drawers-preset e52ef80 || { log "cannot make ../study-code-drawers-preset"; exit 1; }
worktree study-code-training-spread a5a8d2f || { log "cannot make ../study-code-training-spread"; exit 1; }
if ! pgrep -f benchmarks/watch_memory.py > /dev/null; then  # each run's peak memory, one watcher
  nohup .venv/bin/python benchmarks/watch_memory.py --output outputs/study-memory.json --match outputs/ \
    > /dev/null 2>&1 &
fi

RUNNING="pixels-eval/run-(rest|missing).sh"
if pgrep -f "$RUNNING" > /dev/null; then  # started earlier (by hand, or by a former call)
  log "pixels-eval run-rest.sh or run-missing.sh already running: waiting for it to end"
  while pgrep -f "$RUNNING" > /dev/null; do sleep 60; done
else
  log "cores 0 and 1: pixels-eval run-missing.sh"
  pixels_rest 0 &
  first=$!
  sleep 90  # the first process takes the first run; the second then starts on the next one
  pixels_rest 1
  wait "$first"
fi
# A process ends with an error when it met a run the other held; once both have ended, one more pass
# finds every run finished (or resumes what a stop cut), so its status is the study's.
if pixels_rest 1 && pixels_tabulate; then
  log "pixels-eval complete: docs/results/pixels-eval/table.txt"
else
  log "pixels-eval: a run failed, see outputs/pixels-eval-core*.log"
fi
log "core 0: drawers-training-spread-dev; core 1: drawers-preset-dev"
(training_spread 0 || log "drawers-training-spread-dev failed: see outputs/drawers-training-spread-dev.log") &
drawers_preset 1 || log "drawers-preset-dev failed: see outputs/drawers-preset-dev.log"
wait
log "done"
