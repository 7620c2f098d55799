#!/usr/bin/env bash
# No longer started by resume.sh (since 2026-11-27 12:00 UTC): every study of both lanes is complete but
# pixels-eval, which resume.sh then ran from run-rest.sh (complete 2026-11-27 19:56 UTC). Kept as the
# record of how those studies ran.
# The #31 studies queued in two lanes, one per core of the 2-core machine, each study from its frozen
# worktree, each resumable; run again after any stop (a finished study is only re-reported). From
# ../main (resume.sh starts both, each lane once its core's drawer study is done):
#   cp docs/results/queue.sh outputs/queue-running-pixels.sh
#   nohup taskset -c 0 bash outputs/queue-running-pixels.sh pixels >> outputs/queue.log 2>&1 &
# (`taskset`: the studies' frozen `compare --jobs=1` would otherwise give each run 2 torch threads
# beside the other core's study, about 10x slower training; docs/benchmarks.md, "Threads per run";
# run a copy so that editing this file cannot change a running lane). One job at a time per lane:
# - pixels (the default): pixels-bc-dev (../study-code-pixels-bc at af74c16), then its records and its
#   decision copied here and into the pixels-eval worktree; then pixels-eval (../study-code-pixels-eval
#   at f33425a), then its records;
# - plateau: bc-past-plateau-dev (../study-code-bc-plateau at d274b72), then its records and its
#   decision copied into the beyond-plateau-best-bc worktree; then beyond-plateau-best-bc
#   (../study-code-best-bc at 07f4028), then its records and table.
# Each worktree: `git worktree add --detach ../<name> <commit>`, then in it
# `ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs`.
# (Until 2026-11-27 the three first studies ran in one lane on core 0; the lanes change no setting.)
set -euo pipefail
LANE=${1:-pixels}
case "$LANE" in
  pixels | plateau) ;;
  *) echo "Unknown lane '$LANE': give pixels or plateau." >&2; exit 1 ;;
esac
export JOBS=1
# Each run's peak memory (with its env workers) and the machine's lowest available memory, kept in
# outputs/study-memory.json (benchmarks/watch_memory.py; one watcher at a time).
if ! pgrep -f benchmarks/watch_memory.py > /dev/null; then
  nohup .venv/bin/python benchmarks/watch_memory.py --output outputs/study-memory.json --match outputs/ \
    > /dev/null 2>&1 &
fi
copy_report() {  # copy_report STUDY WORKTREE: the report the study's run.sh wrote in its worktree
  mkdir -p "docs/results/$1/report"
  cp -r "../$2/docs/results/$1/report/." "docs/results/$1/report/"
}
pixels_lane() {
  (cd ../study-code-pixels-bc && PYTHONPATH=$PWD bash docs/results/pixels-bc-dev/run.sh)
  copy_report pixels-bc-dev study-code-pixels-bc
  bash docs/results/pixels-bc-dev/save_records.sh
  cp docs/results/pixels-bc-dev/table.txt ../study-code-pixels-eval/docs/results/pixels-bc-dev/table.txt
  (cd ../study-code-pixels-eval && PYTHONPATH=$PWD bash docs/results/pixels-eval/run.sh) \
    >> outputs/pixels-eval.log 2>&1
  copy_report pixels-eval study-code-pixels-eval
  bash docs/results/pixels-eval/save_records.sh
}
plateau_lane() {
  (cd ../study-code-bc-plateau && PYTHONPATH=$PWD bash docs/results/bc-past-plateau-dev/run.sh) \
    >> outputs/bc-past-plateau-dev.log 2>&1
  copy_report bc-past-plateau-dev study-code-bc-plateau
  bash docs/results/bc-past-plateau-dev/save_records.sh
  cp docs/results/bc-past-plateau-dev/table.txt ../study-code-best-bc/docs/results/bc-past-plateau-dev/table.txt
  (cd ../study-code-best-bc && PYTHONPATH=$PWD bash docs/results/beyond-plateau-best-bc/run.sh) \
    >> outputs/beyond-plateau-best-bc.log 2>&1
  bash docs/results/beyond-plateau-best-bc/save_records.sh
}
"${LANE}_lane"
