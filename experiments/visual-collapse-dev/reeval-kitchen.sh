#!/usr/bin/env bash
# The kitchen drawer runs: every saved phase policy evaluated again, 20 episodes per training drawer
# (220 per policy), so that a round's change can be told from noise (the runs' own evaluation used 5
# per drawer, and two nearly identical trainings differed by up to 0.1 on one seed: section 7a).
# Fixed 2026-11-26 before any of these evaluations ran:
#   - policies: outputs/visual-dev/{kitchen,kitchen-balanced,kitchen-epochs}-seed{100,101,102}/policies/round-00{0,1,2}
#     (each one that exists; rerun as runs finish, it skips what is done);
#   - 20 episodes per training drawer, kitchen placement, evaluation seed 9000 for every policy (the same
#     initial states for every phase and variant: paired episode by episode), no env worker process;
#   - per variant, the change of mean success from phase 0 to phases 1 and 2, paired over seeds 100-102
#     (95% t interval; reeval_summary.py prints them);
#   - decision: a variant keeps #28's criterion if its mean success over the 3 seeds at phases 1 and 2
#     is not below its phase 0; among those, the drawer evaluation-seed study trains DAgger the way of
#     the one with the highest mean at phase 2 (uniform on a tie, the simplest); if none keeps it,
#     the report says so and the drawer study is not started before another cause is found.
# From the unseen-rules study's frozen worktree (31ab8b9):
#   cd ../study-code-unseen
#   nohup bash ../main/docs/results/visual-collapse-dev/reeval-kitchen.sh >> outputs/reeval-kitchen.log 2>&1 &
#   (a second instance beside it with REVERSE=1 takes the list from its end; an evaluation in progress
#   leaves NAME.json.partial, which both skip: delete stale .partial files after a kill)
# Table: .venv/bin/python docs/results/visual-collapse-dev/reeval_summary.py outputs/visual-dev/reeval-kitchen
set -euo pipefail
OUT=outputs/visual-dev/reeval-kitchen
mkdir -p "$OUT"
for NAME in kitchen kitchen-balanced kitchen-epochs; do
  ls -d outputs/visual-dev/$NAME-seed10{0,1,2}/policies/round-00{0,1,2} 2>/dev/null || true
done | if [ -n "${REVERSE:-}" ]; then tac; else cat; fi | while read -r POLICY; do
  RUN=$(basename "$(dirname "$(dirname "$POLICY")")")
  TARGET="$OUT/$RUN-$(basename "$POLICY").json"
  [ -f "$TARGET" ] || [ -f "$TARGET.partial" ] && continue
  touch "$TARGET.partial"
  echo "$(date -u +%H:%M:%S) start $RUN $(basename "$POLICY")"
  PYTHONPATH=$PWD OMP_NUM_THREADS=1 MUJOCO_GL=egl .venv/bin/python -m lerobot_mtdagger.cli eval \
    --policy_path="$POLICY" --suite.name=drawers --episodes=20 --seed=9000 --workers=0 \
    --output="$TARGET.partial" > /dev/null < /dev/null
  mv "$TARGET.partial" "$TARGET"
done
echo "$(date -u +%H:%M:%S) done"
