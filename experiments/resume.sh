#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the studies still running, every step resumable, one job per
# core: each study from its own frozen worktree, pinned to its core. Works on a new checkout (no
# outputs/, no worktrees): it makes the worktrees it needs. From ../main, once the README's setup
# command has made .venv, from a copy (bash reads a script as it runs it, so editing this file would
# change a running one):
#   mkdir -p outputs && cp experiments/resume.sh outputs/resume-running.sh
#   nohup bash outputs/resume-running.sh >> outputs/resume.log 2>&1 &
#
# Running (2026-11-28): on core 0 paper-regime-training-dev, then paper-regime-eval (which starts
# only once the former has decided every arm's training); on core 1 plateau-dagger-training-dev, then
# pixels-dagger-epochs-dev (paused until then; it runs from its own commit's docs/results/ layout).
# paper-regime-pertask-dev is complete (skipped at once); drawers-preset-dev stopped (its README).
set -uo pipefail

PLATEAU_COMMIT=${PLATEAU_COMMIT:-fe972b0}  # the commit that added plateau-dagger-training-dev
PERTASK_COMMIT=${PERTASK_COMMIT:-b76672e}  # the commit that added paper-regime-pertask-dev
TRAINING_COMMIT=${TRAINING_COMMIT:-b05f863}  # the commit that added paper-regime-training-dev
EVAL_COMMIT=${EVAL_COMMIT:-ba3f594}  # the commit that added paper-regime-eval
PIXELS_COMMIT=${PIXELS_COMMIT:-a10a67e}  # the commit that added pixels-dagger-epochs-dev

log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

worktree() {  # worktree NAME COMMIT: ../NAME frozen at COMMIT, with this checkout's .venv and outputs/
  if [ ! -d "../$1" ]; then
    git worktree prune
    git worktree add --detach "../$1" "$2" || return 1
  fi
  ln -sf ../main/.venv "../$1/.venv"
  ln -sfn ../main/outputs "../$1/outputs"
}

study() {  # study NAME WORKTREE COMMIT CORE [FOLDER]: runs FOLDER/NAME/run.sh there, pinned to CORE
  local name=$1 tree=$2 commit=$3 core=$4 folder=${5:-experiments}
  worktree "$tree" "$commit" || { log "cannot make ../$tree"; return 1; }
  if pgrep -f "$name/run.sh" > /dev/null; then
    log "$name is already running: stop it first (a second process would share its runs)"
    return 1
  fi
  log "$name on core $core"
  (cd "../$tree" && PYTHONPATH=$PWD JOBS=1 taskset -c "$core" bash "$folder/$name/run.sh") \
    >> "outputs/$name.log" 2>&1
  log "$name ended with status $?"
}

mkdir -p outputs
(study paper-regime-pertask-dev study-code-pertask "$PERTASK_COMMIT" 0 &&
  study paper-regime-training-dev study-code-training "$TRAINING_COMMIT" 0 &&
  study paper-regime-eval study-code-paper-eval "$EVAL_COMMIT" 0) &
(study plateau-dagger-training-dev study-code-plateau-dagger "$PLATEAU_COMMIT" 1 &&
  OMP_NUM_THREADS=1 study pixels-dagger-epochs-dev study-code-pixels-epochs "$PIXELS_COMMIT" 1 docs/results) &
wait
