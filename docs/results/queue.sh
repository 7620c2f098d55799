#!/usr/bin/env bash
# The studies queued on the 2-core machine, each from its frozen worktree, each resumable; run again
# after any stop (a finished study is only re-reported):
#   nohup bash docs/results/queue.sh >> outputs/queue.log 2>&1 &
# 1. pixels-bc-dev (../study-code-pixels-bc at af74c16; --jobs=2), then its records and its decision
#    copied here and into the pixels-eval worktree;
# 2. then, side by side with one job each (one pixel run at a time fits 24 GB with room to spare):
#    pixels-eval (../study-code-pixels-eval at f33425a) and bc-past-plateau-dev
#    (../study-code-bc-plateau at d274b72), then their records.
# Each worktree: `git worktree add --detach ../<name> <commit>`, then in it
# `ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs`. Run from ../main.
set -euo pipefail
# Each run's peak memory (with its env workers) and the machine's lowest available memory, kept in
# outputs/study-memory.json (benchmarks/watch_memory.py; one watcher at a time).
if ! pgrep -f benchmarks/watch_memory.py > /dev/null; then
  nohup .venv/bin/python benchmarks/watch_memory.py --output outputs/study-memory.json --match outputs/ \
    > /dev/null 2>&1 &
fi
(cd ../study-code-pixels-bc && PYTHONPATH=$PWD bash docs/results/pixels-bc-dev/run.sh)
mkdir -p docs/results/pixels-bc-dev/report
cp -r ../study-code-pixels-bc/docs/results/pixels-bc-dev/report/. docs/results/pixels-bc-dev/report/
bash docs/results/pixels-bc-dev/save_records.sh
cp docs/results/pixels-bc-dev/table.txt ../study-code-pixels-eval/docs/results/pixels-bc-dev/table.txt
(cd ../study-code-bc-plateau && PYTHONPATH=$PWD JOBS=1 bash docs/results/bc-past-plateau-dev/run.sh) \
  >> outputs/bc-past-plateau-dev.log 2>&1 &
PLATEAU_PID=$!
(cd ../study-code-pixels-eval && PYTHONPATH=$PWD JOBS=1 bash docs/results/pixels-eval/run.sh) \
  >> outputs/pixels-eval.log 2>&1 &
PIXELS_PID=$!
# Only the two studies: a plain `wait` would also wait on the memory watcher, which never ends.
wait "$PLATEAU_PID" "$PIXELS_PID"
for STUDY in pixels-eval:study-code-pixels-eval bc-past-plateau-dev:study-code-bc-plateau; do
  mkdir -p "docs/results/${STUDY%%:*}/report"
  cp -r "../${STUDY##*:}/docs/results/${STUDY%%:*}/report/." "docs/results/${STUDY%%:*}/report/"
done
bash docs/results/pixels-eval/save_records.sh
bash docs/results/bc-past-plateau-dev/save_records.sh
