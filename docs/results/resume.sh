#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the studies still running, one process pinned to each core of the
# 2-core machine (`taskset`: docs/benchmarks.md, "Threads per run"), every step resumable. Works on a
# new checkout (no outputs/, no worktrees): it makes the frozen worktrees it needs. From ../main, once
# the README's setup command has made .venv, from a copy (bash reads a script as it runs it, so
# editing this file would change a running one):
#   mkdir -p outputs && cp docs/results/resume.sh outputs/resume-running.sh
#   nohup bash outputs/resume-running.sh >> outputs/resume.log 2>&1 &
#
# Core 0: drawers-preset-dev (../study-code-drawers-preset at e52ef80). Core 1:
# drawers-training-spread-dev (../study-code-training-spread at a5a8d2f), then its records and table,
# then pixels-dagger-epochs-dev (../study-code-pixels-epochs at a10a67e).
# (Until 2026-11-27 19:56 UTC it first ran pixels-eval, complete since then, with run-missing.sh; and
# until 12:00 UTC queue.sh's two lanes, all complete.)
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

run_study() {  # run_study CORE WORKTREE STUDY: ../WORKTREE's STUDY run.sh pinned to CORE, then its records
  (cd "../$2" && OMP_NUM_THREADS=1 PYTHONPATH=$PWD taskset -c "$1" \
    bash "docs/results/$3/run.sh") >> "outputs/$3.log" 2>&1
  local status=$?
  bash "docs/results/$3/save_records.sh"
  return "$status"
}

training_spread() {  # drawers-training-spread-dev on CORE, then its records and table
  run_study "$1" study-code-training-spread drawers-training-spread-dev || return 1
  .venv/bin/python docs/results/drawers-training-spread-dev/table.py \
    > docs/results/drawers-training-spread-dev/table.txt
}

mkdir -p outputs
worktree study-code-pixels-epochs a10a67e || { log "cannot make ../study-code-pixels-epochs"; exit 1; }
worktree study-code-drawers-preset e52ef80 || { log "cannot make ../study-code-drawers-preset"; exit 1; }
worktree study-code-training-spread a5a8d2f || { log "cannot make ../study-code-training-spread"; exit 1; }
if ! pgrep -f benchmarks/watch_memory.py > /dev/null; then  # each run's peak memory, one watcher
  nohup .venv/bin/python benchmarks/watch_memory.py --output outputs/study-memory.json --match outputs/ \
    > /dev/null 2>&1 &
fi
if pgrep -f "(drawers-preset|drawers-training-spread|pixels-dagger-epochs)-dev/run.sh" > /dev/null; then
  log "a study is already running: stop it first (a second process would share its runs)"
  exit 1
fi
log "core 0: drawers-preset-dev; core 1: drawers-training-spread-dev, then pixels-dagger-epochs-dev"
(
  training_spread 1 || log "drawers-training-spread-dev failed: see outputs/drawers-training-spread-dev.log"
  run_study 1 study-code-pixels-epochs pixels-dagger-epochs-dev \
    || log "pixels-dagger-epochs-dev failed: see outputs/pixels-dagger-epochs-dev.log"
) &
run_study 0 study-code-drawers-preset drawers-preset-dev \
  || log "drawers-preset-dev failed: see outputs/drawers-preset-dev.log"
wait
log "done"
