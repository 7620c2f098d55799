#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the studies still running, every step resumable, one job per
# core: each study from its own frozen worktree, pinned to its core. Works on a new checkout (no
# outputs/, no worktrees): it makes the worktrees it needs. From ../main, once the README's setup
# command has made .venv, from a copy (bash reads a script as it runs it, so editing this file would
# change a running one):
#   mkdir -p outputs && cp experiments/resume.sh outputs/resume-running.sh
#   nohup bash outputs/resume-running.sh >> outputs/resume.log 2>&1 &
# To change the queue while studies run: stop the earlier copy's chains (its bash processes, not the
# studies' run.sh: `pkill -f outputs/resume-running.sh` before copying), then start the new copy; a
# study still running is waited for, then its core's chain goes on.
#
# paper-regime-eval is complete (2026-11-29 06:03; both cores shared its seeds 2 and 1: each core its
# own `compare` on the same folder, compare skipping the runs another process has finished or is
# writing; a compare that skipped a run the other core was writing ends with an error and no
# results.csv, so core 0's third step tabulates every seed): its steps below are skipped at once. A
# study that refuses to start or stops passes the core to the next one.
# Next (written 2026-11-29 04:50, first used at the next restart): both cores on
# pixels-dagger-epochs-dev (it runs from its own commit's docs/results/ layout): run.sh on core 1
# (epochs, then fixed) and its second_core.sh on core 0 (fixed, then epochs; `shared` retries while the
# other core's compare runs, so the last to end writes the tables); then pixels-matched-eval (it runs
# only if pixels-dagger-epochs-dev's rule says so) with seed 0 on core 0, seed 1 on core 1, and seed 2
# shared. paper-regime-pertask-dev, paper-regime-training-dev, plateau-dagger-training-dev and
# plateau-dagger-eval are complete (their runs are skipped at once); drawers-preset-dev stopped (its
# README).
set -uo pipefail

PLATEAU_COMMIT=${PLATEAU_COMMIT:-fe972b0}  # the commit that added plateau-dagger-training-dev
PERTASK_COMMIT=${PERTASK_COMMIT:-b76672e}  # the commit that added paper-regime-pertask-dev
TRAINING_COMMIT=${TRAINING_COMMIT:-b05f863}  # the commit that added paper-regime-training-dev
EVAL_COMMIT=${EVAL_COMMIT:-ba3f594}  # the commit that added paper-regime-eval
PIXELS_COMMIT=${PIXELS_COMMIT:-a10a67e}  # the commit that added pixels-dagger-epochs-dev
PLATEAU_EVAL_COMMIT=${PLATEAU_EVAL_COMMIT:-631c388}  # the commit that added plateau-dagger-eval
PIXELS_EVAL_COMMIT=${PIXELS_EVAL_COMMIT:-91949d1}  # the commit that added pixels-matched-eval

log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

worktree() {  # worktree NAME COMMIT: ../NAME frozen at COMMIT, with this checkout's .venv and outputs/
  if [ ! -d "../$1" ]; then
    git worktree prune
    git worktree add --detach "../$1" "$2" || return 1
  fi
  ln -sf ../main/.venv "../$1/.venv"
  ln -sfn ../main/outputs "../$1/outputs"
}

study() {  # study NAME WORKTREE COMMIT CORE [FOLDER]: runs FOLDER/NAME/run.sh (or $SCRIPT) there, pinned to CORE
  # With SEEDS set (a study that splits its seeds over cores) only that seed subset. With SEEDS or SHARE
  # set, a second process for it on the same core is refused by a lock, and the other core may work on
  # the same folders (compare shares a folder's runs); otherwise a study that an earlier copy of this
  # script runs is waited for. Returns the study's status.
  local name=$1 tree=$2 commit=$3 core=$4 folder=${5:-experiments} part="" status lock
  local script=${SCRIPT:-$folder/$name/run.sh}
  worktree "$tree" "$commit" || { log "cannot make ../$tree"; return 1; }
  if [ -n "${SEEDS:-}${SHARE:-}" ]; then
    part="${SEEDS:+ (seeds ${SEEDS})}${SHARE:+ (shared)}"
    exec {lock}> "outputs/.$name${SEEDS:+-seeds-${SEEDS// /-}}-core$core.lock"
    flock -n "$lock" || { log "$name$part is already running on core $core: stop it first"; exec {lock}>&-; return 1; }
  elif pgrep -f "$name/run.sh" > /dev/null; then  # started by an earlier copy of this script
    log "$name is already running (a second process would share its runs): waiting for it to end"
    while pgrep -f "$name/run.sh" > /dev/null; do sleep 60; done
    log "$name ended (run by the earlier process)"
    return 0
  fi
  log "$name$part on core $core"
  (cd "../$tree" && PYTHONPATH=$PWD JOBS=1 taskset -c "$core" bash "$script") \
    >> "outputs/$name.log" 2>&1
  status=$?
  [ -n "${lock:-}" ] && exec {lock}>&-
  log "$name$part ended with status $status"
  return "$status"
}

shared() {  # shared NAME WORKTREE COMMIT CORE [FOLDER]: `study` beside the other core's process on the same folders
  # A compare that skipped a run the other core was writing ends with an error (and run.sh with it), so
  # the study runs again every 5 minutes while a compare of NAME runs elsewhere; the last one to end
  # finds every run done and writes the tables.
  local status
  while true; do
    SHARE=1 study "$@"
    status=$?
    [ "$status" -eq 0 ] && return 0
    pgrep -f "lerobot-mtdagger compare .*outputs/$1/" > /dev/null || return "$status"
    sleep 300
  done
}

mkdir -p outputs
SECOND_CORE=$PWD/experiments/pixels-dagger-epochs-dev/second_core.sh  # read as it runs: do not edit meanwhile
(study paper-regime-pertask-dev study-code-pertask "$PERTASK_COMMIT" 0 &&
  study paper-regime-training-dev study-code-training "$TRAINING_COMMIT" 0 &&
  { SEEDS="2" study paper-regime-eval study-code-paper-eval "$EVAL_COMMIT" 0
    SEEDS="1" study paper-regime-eval study-code-paper-eval "$EVAL_COMMIT" 0
    SEEDS="0 1 2" study paper-regime-eval study-code-paper-eval "$EVAL_COMMIT" 0  # tabulates
    OMP_NUM_THREADS=1 SCRIPT=$SECOND_CORE shared pixels-dagger-epochs-dev study-code-pixels-epochs "$PIXELS_COMMIT" 0
    OMP_NUM_THREADS=1 SEEDS="0" study pixels-matched-eval study-code-pixels-matched "$PIXELS_EVAL_COMMIT" 0
    OMP_NUM_THREADS=1 SEEDS="2" shared pixels-matched-eval study-code-pixels-matched "$PIXELS_EVAL_COMMIT" 0; }) &
(study plateau-dagger-training-dev study-code-plateau-dagger "$PLATEAU_COMMIT" 1 &&
  { study plateau-dagger-eval study-code-plateau-eval "$PLATEAU_EVAL_COMMIT" 1
    SEEDS="2" study paper-regime-eval study-code-paper-eval "$EVAL_COMMIT" 1
    SEEDS="1" study paper-regime-eval study-code-paper-eval "$EVAL_COMMIT" 1
    OMP_NUM_THREADS=1 shared pixels-dagger-epochs-dev study-code-pixels-epochs "$PIXELS_COMMIT" 1 docs/results
    OMP_NUM_THREADS=1 SEEDS="1" study pixels-matched-eval study-code-pixels-matched "$PIXELS_EVAL_COMMIT" 1
    OMP_NUM_THREADS=1 SEEDS="2" shared pixels-matched-eval study-code-pixels-matched "$PIXELS_EVAL_COMMIT" 1; }) &
wait
