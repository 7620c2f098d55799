#!/usr/bin/env bash
# Evaluation seeds 0-2, MetaWorld MT10 pixels (`--preset=metaworld-pixels`, 84 px RGB): BC at every
# budget, Uniform DAgger, MTDAgger-TN (need) and MTDAgger-PG (gain). Settings fixed on 2026-11-26
# before any evaluation-seed pixel run, from the development-seed studies:
#   - the preset as it is at the commit that froze this file (10 demos per task in round 0, 5 DAgger
#     rounds of 10 per task, beta 0.5 then 0, 1 500 warm-started steps per phase at batch 64, lr 3e-4,
#     n_min 2; DAgger batches balanced over tasks: ../visual-collapse-dev 6b-6c);
#   - 20 evaluation episodes per task after every phase (200 per phase), BC at every budget DAgger
#     has a point at (10, 20, ..., 60 demos per task; BC at the budget of round k trains (k + 1) x 1 500
#     steps);
#   - BC's batch sampling: the one ../pixels-bc-dev's rule chooses (read below from its table.txt,
#     written by its save_records.sh; this script refuses to start before that study has decided);
#   - levels 0.6 and 0.7 for the demos-to-reach tables.
# Primary outcome, fixed with them: need - BC and need - uniform in mean success over the budgets
# 20-60 demos per task (need's and uniform's phases 1-5, BC's budgets 20-60), paired over the 3 seeds,
# 95% t interval. Secondary: gain - BC and gain - uniform on the same window; success on the three
# hardest tasks (by uniform's phase-0 success, not by BC's final one); demos and frames to reach 0.6
# and 0.7. Seeds 3-4 are added only if the first three finish with time to spare, and said so.
#
# Cost (the pixel preset run of docs/benchmarks.md, 33 min alone with 50 evaluation episodes per
# phase; 200 per phase add about 17 min): about 50-60 min per DAgger run and 12-30 min per BC run on
# one core: ~15 core-hours, ~7.5 h at --jobs=2 (three sessions). Memory: two pixel runs at once need
# the training-side fix of 2026-11-26 (docs/benchmarks.md, "Peak memory of a visual run's training
# phases"); check `free -g` while two DAgger runs are in their last rounds. (Added after the freeze,
# a comment only: ../queue.sh runs it with JOBS=1 beside another study.)
#
# Run ONCE, from a frozen worktree at the commit that added this file:
#   git worktree add --detach ../study-code-pixels-eval <commit>; cd ../study-code-pixels-eval
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   cp ../main/docs/results/pixels-bc-dev/table.txt docs/results/pixels-bc-dev/table.txt  # the decision
#   PYTHONPATH=$PWD nohup bash docs/results/pixels-eval/run.sh >> outputs/pixels-eval.log 2>&1 &
# Resumable (finished runs are skipped, cut-off runs resumed). After each session:
#   bash docs/results/pixels-eval/save_records.sh   (from ../main; commit what it writes)
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/pixels-eval
DECISION=$(sed -n 's/^Decision: BC samples \([a-z]*\).*/\1/p' docs/results/pixels-bc-dev/table.txt)
if [ -z "$DECISION" ]; then
  echo "docs/results/pixels-bc-dev/table.txt holds no decision yet: finish that study first." >&2
  exit 1
fi
echo "BC samples $DECISION (docs/results/pixels-bc-dev/table.txt)"
# The preset samples DAgger batches balanced and BC batches uniformly; --training.sampling=balanced
# makes BC's balanced too and leaves DAgger's as they are, so one compare holds every method.
BC_SAMPLING=()
if [ "$DECISION" != uniform ]; then BC_SAMPLING=(--training.sampling="$DECISION"); fi
"$CLI" compare --methods='[bc,uniform,need,gain]' --seeds='[0,1,2]' --jobs="${JOBS:-2}" \
  --preset=metaworld-pixels --rollout.eval_episodes=20 --progress=false "${BC_SAMPLING[@]}" \
  --output_dir="$OUT"
"$CLI" report --compare_dir="$OUT" --levels='[0.6,0.7]' --output_dir=docs/results/pixels-eval/report
