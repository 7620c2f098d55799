#!/usr/bin/env bash
# The 5 runs this study adds (narrow at 10 demos is visual-collapse-dev's hold-seed100 phase 0),
# two at a time, largest first. From the frozen worktree:
#   OMP_NUM_THREADS=1 nohup bash ../main/docs/results/drawer-placement-dev/run-all.sh > outputs/placement-dev.log 2>&1 &
set -uo pipefail
mkdir -p outputs/placement-dev
printf '%s\n' "kitchen 60" "narrow 60" "kitchen 30" "narrow 30" "kitchen 10" |
  xargs -P 2 -L 1 bash -c 'nice -n 10 bash ../main/docs/results/drawer-placement-dev/run.sh "$0" "$1" 100 \
    > "outputs/placement-dev/bc-$0-$1demos-seed100.log" 2>&1; echo "$0 $1 exit $?"'
