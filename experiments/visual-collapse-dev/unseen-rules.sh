#!/usr/bin/env bash
# Does the unseen drawers' decline over the DAgger rounds come from the shared "any drawer" embedding?
# Every saved phase policy of the kitchen runs (run-kitchen.sh, seeds 100-102, phases 0-2) is evaluated
# on the 4 unseen drawers under both rules of `eval --unseen_rule`: `shared` (the embedding trained with
# task dropout 0.1; what the runs' own unseen evaluation uses) and `nearest` (the task input of the
# training drawer with the most alike handle; docs/drawers.md). 20 episodes per drawer, the same
# evaluation seed 9000 for every policy and rule (the same initial states: paired episode by episode),
# kitchen placement. Fixed 2026-11-26 before any of these evaluations; table and outcomes:
#   .venv/bin/python docs/results/visual-collapse-dev/unseen_rules_summary.py outputs/visual-dev/unseen-rules
# From a frozen worktree at 31ab8b9 (the first commit with --unseen_rule):
#   git worktree add --detach ../study-code-unseen 31ab8b9; cd ../study-code-unseen
#   ln -sf ../main/.venv .venv && ln -sfn ../main/outputs outputs
#   nohup bash ../main/docs/results/visual-collapse-dev/unseen-rules.sh >> outputs/unseen-rules.log 2>&1 &
# Rerun after a stop: finished evaluations are kept, policies not yet trained are skipped, and an
# evaluation another instance is running (its .partial file) is left to it (delete stale ones first).
set -euo pipefail
OUT=outputs/visual-dev/unseen-rules
mkdir -p "$OUT"
for SEED in 100 101 102; do
  for PHASE in 0 1 2; do
    POLICY="outputs/visual-dev/kitchen-seed$SEED/policies/round-00$PHASE"
    [ -d "$POLICY" ] || continue
    for RULE in shared nearest; do
      TARGET="$OUT/kitchen-seed$SEED-phase$PHASE-$RULE.json"
      [ -f "$TARGET" ] || [ -f "$TARGET.partial" ] && continue
      touch "$TARGET.partial"
      echo "$(date -u +%H:%M:%S) start seed $SEED phase $PHASE $RULE"
      PYTHONPATH=$PWD OMP_NUM_THREADS=1 MUJOCO_GL=egl .venv/bin/python -m lerobot_mtdagger.cli eval \
        --policy_path="$POLICY" --suite.name=drawers --suite.tasks='[heldout]' --unseen_rule="$RULE" \
        --episodes=20 --seed=9000 --workers=1 --output="$TARGET.partial" > /dev/null
      mv "$TARGET.partial" "$TARGET"
    done
  done
done
echo "$(date -u +%H:%M:%S) done"
