#!/usr/bin/env bash
# Development seeds (100-102), MT10 pixels (`--preset=metaworld-pixels`): which batch sampling gives BC
# its best training at 10, 30 and 60 demos per task? The evaluation-seed pixel study (#31 part 3) runs
# BC at every budget beside Uniform DAgger, MTDAgger-TN and MTDAgger-PG; its BC must be a baseline
# that does not lose success when given more data.
#
# Settings fixed on 2026-11-26 before any run: the preset as it is at the commit that added this file
# (84 px RGB, 1 500 steps per phase at batch 64, lr 3e-4; BC at the budget of round k trains
# (k + 1) x 1 500 steps, as long as the DAgger policy at that budget), 20 evaluation episodes per task,
# BC at 10, 30 and 60 demos per task, two samplings:
#   uniform     frames uniformly (the preset's BC; better than balanced at 10 demos on these seeds:
#               0.680 against 0.627, docs/results/visual-collapse-dev 6c);
#   balanced    a task uniformly, then one of its frames (the preset's DAgger sampling).
# Decision rule, fixed with them: the evaluation study's BC takes the sampling with the highest 3-seed
# mean success over the three budgets among those whose mean at 60 is not below their mean at 10 by
# more than 0.01; if neither qualifies, the highest mean, said so, and the BC training is studied
# further before any evaluation-seed run.
#
# Cost (estimate from the 2026-11-26 pixel runs, alone on a core: 100 episodes collected and written
# in about 100 s, 1 500 steps in about 115 s, 20 evaluation episodes per task in about 8 min): BC at
# 10 / 30 / 60 demos about 12 / 20 / 30 min of one core; 2 samplings x 3 seeds, about 6 core-hours,
# 3 h of wall time at --jobs=2 alone.
# From a worktree at the commit that added this file:
#   git worktree add --detach ../study-code-pixels-bc <commit>; cd ../study-code-pixels-bc
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   PYTHONPATH=$PWD nohup bash docs/results/pixels-bc-dev/run.sh >> outputs/pixels-bc-dev.log 2>&1 &
# Resumable (finished runs are skipped). Then `report` on each folder's results.csv (below).
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/pixels-bc-dev
COMMON=(--methods='[bc]' --seeds='[100,101,102]' --jobs="${JOBS:-2}" --preset=metaworld-pixels
  --bc_budgets='[10,30,60]' --rollout.eval_episodes=20 --progress=false)
"$CLI" compare "${COMMON[@]}" --training.sampling=uniform --output_dir="$OUT/uniform"
"$CLI" compare "${COMMON[@]}" --training.sampling=balanced --output_dir="$OUT/balanced"
"$CLI" report --compare_dir="$OUT/uniform" --variants="{bc-balanced: $OUT/balanced}" \
  --output_dir=docs/results/pixels-bc-dev/report
