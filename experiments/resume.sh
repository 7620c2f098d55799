#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the studies still running, every step resumable. Works on a new
# checkout (no outputs/, no worktrees): it makes the frozen worktree it needs. From ../main, once the
# README's setup command has made .venv, from a copy (bash reads a script as it runs it, so editing
# this file would change a running one):
#   mkdir -p outputs && cp experiments/resume.sh outputs/resume-running.sh
#   nohup bash outputs/resume-running.sh >> outputs/resume.log 2>&1 &
#
# Nothing is running (2026-11-28 05:19 UTC): paper-regime-calibration-dev is complete, and run again
# it only re-reports (every step is skipped or resumed as finished). The script is kept as the way to
# start the next study from its frozen worktree. (Until 2026-11-28 this script ran drawers-preset-dev,
# now stopped, drawers-training-spread-dev, complete, and pixels-dagger-epochs-dev, paused: see their
# READMEs.)
set -uo pipefail

CALIBRATION_COMMIT=${CALIBRATION_COMMIT:-83268c0}  # the commit that added paper-regime-calibration-dev

log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

worktree() {  # worktree NAME COMMIT: ../NAME frozen at COMMIT, with this checkout's .venv and outputs/
  if [ ! -d "../$1" ]; then
    git worktree prune
    git worktree add --detach "../$1" "$2" || return 1
  fi
  ln -sf ../main/.venv "../$1/.venv"
  ln -sfn ../main/outputs "../$1/outputs"
}

mkdir -p outputs
worktree study-code-calibration "$CALIBRATION_COMMIT" || { log "cannot make ../study-code-calibration"; exit 1; }
if pgrep -f "paper-regime-calibration-dev/run.sh" > /dev/null; then
  log "the study is already running: stop it first (a second process would share its runs)"
  exit 1
fi
log "paper-regime-calibration-dev on both cores"
(cd ../study-code-calibration && PYTHONPATH=$PWD bash experiments/paper-regime-calibration-dev/run.sh) \
  >> outputs/paper-regime-calibration-dev.log 2>&1
status=$?
log "paper-regime-calibration-dev ended with status $status"
