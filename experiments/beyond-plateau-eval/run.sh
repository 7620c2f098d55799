#!/usr/bin/env bash
# Evaluation seeds 0-4, MT10 state: does DAgger keep rising past the level where one-round BC levels
# off? Proposed by the development-seed pilot (../beyond-plateau-dev/README.md), whose decision rule
# was met. Settings fixed on 2026-11-25 before any evaluation-seed run of it, from the pilot's design:
# the `small` preset (the MT10 study's), the default protocol, 20 DAgger rounds (up to 63 demos per
# task), 20 evaluation episodes per task, need and uniform, BC at 12, 21, 33, 45 and 63 demos per task.
# Primary outcome, fixed with them: need - BC in mean success over 45-63 demos per task (need: its 7
# phases there; BC: its 45 and 63 budgets), paired over the 5 seeds with a 95% t interval
# (`../beyond-plateau-dev/table.py docs/results/beyond-plateau-eval/report/results.csv`). Secondary:
# need - uniform on the same window, and demos per task to reach 95%.
#
# Run ONCE, from a frozen worktree (README.md here); resumable (finished runs are skipped, cut-off
# runs resumed):
#   nohup bash docs/results/beyond-plateau-eval/run.sh >> outputs/beyond-plateau-eval.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/beyond-plateau-eval
"$CLI" compare --methods='[need,bc,uniform]' --seeds='[0,1,2,3,4]' --jobs=2 --preset=small --rounds=20 \
  --bc_budgets='[12,21,33,45,63]' --eval_episodes=20 --progress=false --output_dir="$OUT"
"$CLI" report --compare_dir="$OUT" --levels='[0.8,0.9,0.95]' --output_dir=docs/results/beyond-plateau-eval/report
