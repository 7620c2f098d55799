#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the #31 studies, one sequence per core of the 2-core machine,
# each step pinned with `taskset` (docs/benchmarks.md, "Threads per run") and resumable. From ../main:
#   nohup bash docs/results/resume.sh >> outputs/resume.log 2>&1 &
# Every step first waits while a process of the same step is still running (started by an earlier
# call), then runs it: a step whose runs are finished only rewrites its tables, a cut one resumes.
#
# Core 1: queue.sh's plateau lane (bc-past-plateau-dev, then beyond-plateau-best-bc), then a second
#   pixels-eval process beside core 0's (once pixels-bc-dev has decided; each compare skips the runs
#   the other finished and fails at once on one the other holds), then pixels-eval once more for its
#   table and report, then drawers-preset-dev (../study-code-drawers-preset).
# Core 0: queue.sh's pixels lane (pixels-bc-dev, then pixels-eval).
# A lane runs from a copy (outputs/queue-running-<lane>.sh) so that editing queue.sh cannot change it.
# (Until 2026-11-27 07:01 UTC both cores first ran the drawers-eval study, now complete.)
# Worktrees as their READMEs say: `git worktree add --detach ../<name> <commit>`, then in it
# `ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs`.
set -uo pipefail

wait_while_running() {  # wait_while_running PATTERN: until no process's command line matches
  while pgrep -f -- "$1" > /dev/null; do sleep 60; done
}

log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

queue_lane() {  # queue_lane CORE LANE: queue.sh's lane, from a copy, once no copy of it runs
  wait_while_running "outputs/queue-running-$2.sh"
  log "core $1: queue.sh's $2 lane"
  cp docs/results/queue.sh "outputs/queue-running-$2.sh"
  taskset -c "$1" bash "outputs/queue-running-$2.sh" "$2" >> "outputs/queue-$2.log" 2>&1 \
    || log "core $1: the $2 lane stopped with an error: see outputs/queue-$2.log"
}

PIXELS_EVAL=../study-code-pixels-eval

pixels_eval() {  # pixels_eval CORE: pixels-eval's frozen run.sh, one job pinned to CORE
  (cd "$PIXELS_EVAL" && JOBS=1 PYTHONPATH=$PWD taskset -c "$1" bash docs/results/pixels-eval/run.sh) \
    >> outputs/pixels-eval-second.log 2>&1
}

pixels_eval_second_process() {  # pixels_eval_second_process CORE: beside the pixels lane, then the report
  until grep -q "^Decision: BC samples" "$PIXELS_EVAL/docs/results/pixels-bc-dev/table.txt" 2> /dev/null; do
    sleep 300
  done
  log "core $1: pixels-eval, a second process beside the pixels lane's"
  pixels_eval "$1" || log "core $1: pixels-eval's second process ended with an error (a run the other held?)"
  wait_while_running "outputs/queue-running-pixels.sh"
  log "core $1: pixels-eval once more (its table and report), then its records"
  pixels_eval "$1" || { log "core $1: pixels-eval failed: see outputs/pixels-eval-second.log"; return 1; }
  mkdir -p docs/results/pixels-eval/report
  cp -r "$PIXELS_EVAL/docs/results/pixels-eval/report/." docs/results/pixels-eval/report/
  bash docs/results/pixels-eval/save_records.sh
}

core1() {
  queue_lane 1 plateau
  pixels_eval_second_process 1
  log "core 1: drawers-preset-dev"
  (cd ../study-code-drawers-preset && OMP_NUM_THREADS=1 PYTHONPATH=$PWD taskset -c 1 \
    bash docs/results/drawers-preset-dev/run.sh >> outputs/drawers-preset-dev.log 2>&1)
  log "core 1: done"
}

core0() {
  queue_lane 0 pixels
  log "core 0: done"
}

core1 &
core0 &
wait
