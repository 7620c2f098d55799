#!/usr/bin/env bash
# Runs a command with every running study paused, so that it gets the cores and the studies' phase
# wall times stay clean; then says when they were paused, for the study READMEs. From the repository
# root:
#   bash experiments/with_studies_paused.sh .venv/bin/python -m pytest
# Pauses (SIGSTOP) the runs themselves (`python -m lerobot_mtdagger.cli run`, as `compare` starts them,
# and `lerobot-mtdagger run` started by hand) with their env workers, and always resumes (SIGCONT) them,
# whatever the command does. The window goes to stdout and to STUDY_PAUSE_LOG
# (default outputs/study-pauses.log). Exits with the command's status.
set -uo pipefail
if [ "$#" -eq 0 ]; then
  echo "Give the command to run, e.g. bash experiments/with_studies_paused.sh .venv/bin/python -m pytest" >&2
  exit 2
fi
PATTERN=${STUDY_PATTERN:-"lerobot_mtdagger\.cli run|lerobot-mtdagger run"}
LOG=${STUDY_PAUSE_LOG:-outputs/study-pauses.log}

study_processes() {  # the runs and every process they started (env workers), one pid a line
  local pids
  pids=$(pgrep -f -- "$PATTERN" || true)
  for pid in $pids; do
    echo "$pid"
    pgrep -P "$pid" || true
  done
}

PAUSED=$(study_processes | sort -u)
START=$(date -u +%FT%H:%M:%S)
resume() {
  # shellcheck disable=SC2086  # one pid a word
  [ -n "$PAUSED" ] && kill -CONT $PAUSED 2> /dev/null
  local line
  line="paused $(echo "$PAUSED" | grep -c .) study process(es) $START-$(date -u +%H:%M:%S) for: $*"
  echo "$line"
  mkdir -p "$(dirname "$LOG")" && echo "$line" >> "$LOG"
}
wait_stopped() {  # until each paused process is stopped, at most about 5 s in all: a process handles
  # SIGSTOP when it next runs, which on a loaded machine may be a moment after kill returns
  local pid state tries=0
  for pid in $PAUSED; do
    while [ "$tries" -lt 100 ]; do
      state=$(cut -d')' -f2 "/proc/$pid/stat" 2> /dev/null | cut -d' ' -f2) || break
      [ -z "$state" ] || [ "$state" = T ] && break  # stopped, or gone
      sleep 0.05
      tries=$((tries + 1))
    done
  done
}
trap 'resume "$@"' EXIT
trap 'exit 130' INT TERM
# shellcheck disable=SC2086
[ -n "$PAUSED" ] && kill -STOP $PAUSED && wait_stopped
"$@"
