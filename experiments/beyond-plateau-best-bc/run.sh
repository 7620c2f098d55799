#!/usr/bin/env bash
# Evaluation seeds 0-4, MT10 state: the best BC of ../bc-past-plateau-dev on the beyond-plateau study's
# evaluation seeds (#31: "need beats BC past the plateau" is a result only against a BC that does not
# lose success when given more data). Settings fixed on 2026-11-27 before any run of it, and before
# ../bc-past-plateau-dev had finished a run:
#   - the training: the one ../bc-past-plateau-dev's rule picks (read below from its table.txt, written
#     by its save_records.sh; this script refuses to start before that study has decided);
#   - everything else as ../beyond-plateau-eval/run.sh fixed it for its BC: the `small` preset, 20 DAgger
#     rounds' budgets (BC trained as long as the DAgger policy at the same budget), 20 evaluation
#     episodes per task, evaluation seeds 0-4; the budgets 33, 45 and 63 demos per task (#31's).
#   - if the rule picks plain BC, these runs would repeat ../beyond-plateau-eval's BC (same training,
#     seeds and budgets): nothing is run, and the secondary outcome below equals the primary one.
# Secondary outcome of ../beyond-plateau-eval, fixed with them: need - best BC in mean success over
# 45-63 demos per task (need: its phases there, from ../beyond-plateau-eval/report/results.csv; best BC:
# its 45 and 63 budgets), paired over the 5 seeds, 95% t interval; beside it, best BC - plain BC on the
# same window and best BC's change from 33 to 63 demos per seed (table.py).
#
# Cost (estimate: plain BC at 33/45/63 took about 10/14/20 min of one core; the plateau stop may train
# longer): about 15 runs x 15 min, about 4 core-hours.
# Run ONCE, from a frozen worktree at the commit that added this file:
#   git worktree add --detach ../study-code-best-bc <commit>; cd ../study-code-best-bc
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   cp ../main/docs/results/bc-past-plateau-dev/table.txt docs/results/bc-past-plateau-dev/table.txt  # the decision
#   PYTHONPATH=$PWD nohup bash docs/results/beyond-plateau-best-bc/run.sh >> outputs/beyond-plateau-best-bc.log 2>&1 &
# Resumable (finished runs are skipped, cut-off runs resumed). After each session, from ../main:
#   bash docs/results/beyond-plateau-best-bc/save_records.sh   (commit what it writes)
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/beyond-plateau-best-bc
DECISION=$(sed -n 's/^Decision: the best BC is \([a-z]*\).*/\1/p' docs/results/bc-past-plateau-dev/table.txt)
case "$DECISION" in
  plain)
    echo "The best BC is plain BC: its evaluation-seed runs are ../beyond-plateau-eval's; nothing to run."
    exit 0
    ;;
  balanced) TRAINING=(--training.sampling=balanced) ;;
  cosine) TRAINING=(--training.lr_schedule=cosine) ;;
  plateau) TRAINING=(--training.steps_rule=plateau) ;;
  *)
    echo "docs/results/bc-past-plateau-dev/table.txt holds no decision yet: finish that study first." >&2
    exit 1
    ;;
esac
echo "The best BC is $DECISION (docs/results/bc-past-plateau-dev/table.txt): ${TRAINING[*]}"
"$CLI" compare --methods='[bc]' --seeds='[0,1,2,3,4]' --jobs="${JOBS:-2}" --preset=small --dagger.rounds=20 \
  --bc_budgets='[33,45,63]' --rollout.eval_episodes=20 --progress=false "${TRAINING[@]}" \
  --output_dir="$OUT/$DECISION"
