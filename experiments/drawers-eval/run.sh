#!/usr/bin/env bash
# Evaluation seeds 0-2, point-cloud drawers (kitchen placement): BC at every budget, Uniform DAgger,
# MTDAgger-TN (need), TN without the Kalman filter (need_raw) and MTDAgger-PG (gain), each evaluated
# on the 11 training drawers and the 4 unseen ones after every phase. Settings fixed on 2026-11-26
# before any evaluation-seed drawer run, from the development-seed studies:
#   - the reduced drawer run of ../visual-collapse-dev (sections 5 and 7, seeds 100-102):
#     `--preset=drawers-pointcloud` (512 points, batch 64, lr 3e-4, n_min 2, kitchen placement, task
#     dropout 0.1 for the unseen drawers' shared embedding) with 10 demos per drawer in round 0 and 2
#     DAgger rounds of 10 per drawer (beta 0.5, then 0): phases at 10 / 20 / 30 demos per drawer;
#   - DAgger training: warm-started phases of `--training.steps_rule=epochs --training.epochs=12.4`
#     passes over the phase's frames (1 500 steps on round 0's data), the variant that
#     ../visual-collapse-dev/reeval-kitchen.sh's fixed rule chose (section 7a: on 220 episodes per
#     policy, 0.885 -> 0.962 -> 0.967 over seeds 100-102, where 1 500 steps per phase gave 0.909 ->
#     0.909 -> 0.893 and balanced sampling stayed lower);
#   - BC: one training on its final data with the same rule, from scratch, at 10, 20 and 30 demos per
#     drawer, IF ../drawer-placement-dev/run-epochs.sh's fixed rule keeps it (kitchen BC at 60 demos
#     not below its mean at 10 by more than 0.02; line `Decision:` of ../drawer-placement-dev/table.txt).
#     Until that line says `epochs`, STAGE=bc refuses to start;
#   - 20 evaluation episodes per training drawer (220) and per unseen drawer (80) after every phase,
#     seeded by the run's seed (every method of a seed sees the same initial states);
#   - levels 0.9 and 0.95 for the demos-to-reach tables.
# Primary outcome, fixed with them: need - BC and need - uniform in mean in-domain success over 20-30
# demos per drawer (the DAgger methods' phases 1-2, BC's budgets 20 and 30), paired over seeds 0-2,
# 95% t interval. Secondary: need - need_raw, gain - BC, gain - uniform, uniform - BC on the same
# window; the same differences in unseen success; demos and expert frames to reach 0.9 and 0.95.
# table.py computes them from the report's results.csv. Seeds 3-4 only if 0-2 finish with time to
# spare, and said so.
#
# Cost (the kitchen runs of ../visual-collapse-dev, one core beside another run): a DAgger run about
# 35-40 min (per phase about 2 min collecting, 2-6 min training, 6 min evaluating 300 episodes), a BC
# run 10-17 min: 12 DAgger runs and 9 BC runs, about 9.5 core-hours.
#
# Run from a frozen worktree at the commit that added this file, one stage per core:
#   git worktree add --detach ../study-code-drawers-eval <commit>; cd ../study-code-drawers-eval
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   STAGE=dagger OMP_NUM_THREADS=1 PYTHONPATH=$PWD nohup bash docs/results/drawers-eval/run.sh \
#     >> outputs/drawers-eval-dagger.log 2>&1 &
#   # once ../drawer-placement-dev/table.txt holds the BC decision (copy it into the worktree):
#   STAGE=bc OMP_NUM_THREADS=1 PYTHONPATH=$PWD nohup bash docs/results/drawers-eval/run.sh \
#     >> outputs/drawers-eval-bc.log 2>&1 &
#   STAGE=report bash docs/results/drawers-eval/run.sh   # when both are done
# Resumable (finished runs are skipped, cut-off runs resumed). After each session, from ../main:
#   bash docs/results/drawers-eval/save_records.sh   (commit what it writes)
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/drawers-eval
COMMON=(--seeds='[0,1,2]' --jobs=1 --preset=drawers-pointcloud --dagger.rounds=2
  --dagger.budget_per_task=10 --training.steps_rule=epochs --training.epochs=12.4
  --rollout.eval_episodes=20 --rollout.workers=1 --progress=false)
case "${STAGE:-}" in
  dagger)
    "$CLI" compare --methods='[uniform,need,need_raw,gain]' "${COMMON[@]}" --output_dir="$OUT/dagger"
    ;;
  bc)
    DECISION=$(sed -n 's/^Decision: BC steps \([a-z]*\) .*/\1/p' docs/results/drawer-placement-dev/table.txt)
    if [ "$DECISION" != epochs ]; then
      echo "docs/results/drawer-placement-dev/table.txt does not choose epochs for BC (got '$DECISION'):" \
        "finish run-epochs.sh, or study BC's training further, before BC runs here." >&2
      exit 1
    fi
    "$CLI" compare --methods='[bc]' "${COMMON[@]}" --output_dir="$OUT/bc"
    ;;
  report)
    "$CLI" report --results="[$OUT/dagger,$OUT/bc]" --levels='[0.9,0.95]' \
      --output_dir=docs/results/drawers-eval/report
    .venv/bin/python docs/results/drawers-eval/table.py > docs/results/drawers-eval/table.txt
    ;;
  *)
    echo "Set STAGE=dagger, bc or report (see the comments at the top)." >&2
    exit 1
    ;;
esac
