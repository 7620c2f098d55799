#!/usr/bin/env bash
# Development seeds (100-102), MT10 state: which BC training keeps its success as the demonstrations
# grow past 33 per task? (#31: on the evaluation seeds plain BC fell from 33 to 45 demos per task on 4
# of 5 seeds, so "need beats BC past the plateau" is a result only against a BC that does not drop.)
#
# Settings fixed on 2026-11-26 before any run: the beyond-plateau study's (`small` preset, 20 DAgger
# rounds' budgets, BC trained as long as the DAgger policy at the same budget, 20 evaluation episodes
# per task), BC at 33, 45 and 63 demos per task, four trainings:
#   plain       the default (uniform frame sampling, constant learning rate, fixed steps);
#   balanced    --training.sampling=balanced (the second BC baseline of the MT10 and MT50 studies);
#   cosine      --training.lr_schedule=cosine (the rate decayed to 0 over the phase);
#   plateau     --training.steps_rule=plateau (until the held-out loss stops improving; 20% of each
#               task's episodes held out, measured every 200 steps, patience 5, at most 20 000).
# Decision rule, fixed with them: the best BC is the training with the highest 3-seed mean success over
# 33-63 demos among those whose mean at 63 is not below their mean at 33 by more than 0.01; if none
# qualifies, the highest mean, said so. It is then run ONCE on the evaluation seeds 0-4 at 33, 45 and
# 63 demos, and need - best BC over 45-63 is reported as a secondary outcome beside the primary one
# fixed in ../beyond-plateau-eval/run.sh.
#
# Cost (estimate from the beyond-plateau pilot: BC at 33/45/63 demos took about 10/14/20 min of one
# core): 4 trainings x 3 seeds x 3 budgets, about 9 core-hours, 4-5 h of wall time at --jobs=2 alone.
# From a worktree at the commit that added this file (the code must have --training.lr_schedule):
#   git worktree add --detach ../study-code-bc-plateau <commit>; cd ../study-code-bc-plateau
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   PYTHONPATH=$PWD nohup bash docs/results/bc-past-plateau-dev/run.sh >> outputs/bc-past-plateau-dev.log 2>&1 &
# Resumable (finished runs are skipped). Then: python docs/results/beyond-plateau-dev/table.py on each
# variant's results.csv, and `report --compare_dir=.../plain --variants='{...}'` for the figures.
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/bc-past-plateau-dev
COMMON=(--methods='[bc]' --seeds='[100,101,102]' --jobs="${JOBS:-2}" --preset=small --dagger.rounds=20
  --bc_budgets='[33,45,63]' --rollout.eval_episodes=20 --progress=false)
"$CLI" compare "${COMMON[@]}" --output_dir="$OUT/plain"
"$CLI" compare "${COMMON[@]}" --training.sampling=balanced --output_dir="$OUT/balanced"
"$CLI" compare "${COMMON[@]}" --training.lr_schedule=cosine --output_dir="$OUT/cosine"
"$CLI" compare "${COMMON[@]}" --training.steps_rule=plateau --output_dir="$OUT/plateau"
"$CLI" report --compare_dir="$OUT/plain" --variants="{bc-balanced: $OUT/balanced, bc-cosine: $OUT/cosine, bc-plateau: $OUT/plateau}" \
  --output_dir=docs/results/bc-past-plateau-dev/report
