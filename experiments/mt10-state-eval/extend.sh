#!/usr/bin/env bash
# MT10 state, evaluation seeds 0-4: the runs of run.sh extended from 6 to 10 DAgger rounds (up to 33
# demos per task), and BC (plain and balanced) at the four new budgets 24, 27, 30 and 33.
#
# Decided on 2026-11-22 AFTER the 6-round results: no DAgger method had reached 90% on more than 2 of
# 5 seeds and every one was still rising at 21 demos, and the study is to run "enough rounds to pass
# 90% or to show where each method levels off". Nothing else changes: the same preset, seeds and
# evaluation episodes, and rounds 0-6 of every run are kept as they are (a DAgger run resumed with
# more --rounds makes the rounds a run started with that number makes; tests/test_toy.py). The
# 10-round length is the metaworld-state preset's, fixed before any MT10 result.
#
# Run ONCE, from a frozen worktree (README, "How the runs were made"); resumable. From its root:
#   nohup bash docs/results/mt10-state-eval/extend.sh >> outputs/mt10-state-eval.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/mt10-state-eval
"$CLI" compare --methods='[bc,uniform,need,need_raw,gain]' --seeds='[0,1,2,3,4]' --jobs=2 \
  --output_dir="$OUT" --preset=small --rounds=10 --eval_episodes=20 --progress=false
"$CLI" compare --methods='[bc]' --seeds='[0,1,2,3,4]' --jobs=2 \
  --bc_budgets='[3,6,9,12,15,18,21,24,27,30,33]' --output_dir="$OUT-bc-balanced" --preset=small \
  --rounds=10 --eval_episodes=20 --progress=false --sampling=balanced
