#!/usr/bin/env bash
# Behaviour check for a change that must not alter results: four small runs (toy; MT10 state with the
# performance-gain scheduler; point-cloud drawers with an unseen-task evaluation; ACT as the student)
# made from a code tree, to compare with the same four made from another tree:
#   git worktree add --detach ../before <old commit>
#   bash scripts/refactor_check.sh ../before outputs/check/before
#   bash scripts/refactor_check.sh . outputs/check/after
#   for r in toy state pointcloud act; do
#     .venv/bin/python scripts/compare_experiments.py outputs/check/before/$r outputs/check/after/$r
#   done
# Each run is skipped when its folder exists. About 10 min on 2 idle cores (the point-cloud run most).
# Each run uses one thread (OMP_NUM_THREADS=1 unless set): with two, ACT's CPU training differs between
# two runs of the same code in the last digits (250 differences in its weights and losses), with one
# it is the same to the bit.
set -euo pipefail
TREE=$(cd "${1:?give the code tree, e.g. ../before}" && pwd)
OUT=$(mkdir -p "${2:?give the output folder}" && cd "$2" && pwd)
PYTHON=${PYTHON:-$PWD/.venv/bin/python}
cd "$TREE"
run() {  # run NAME OPTIONS...: one run of TREE's code into OUT/NAME, unless it exists
  local name=$1; shift
  [ -d "$OUT/$name" ] && return 0
  OMP_NUM_THREADS=${OMP_NUM_THREADS:-1} MUJOCO_GL=egl PYTHONPATH=$TREE "$PYTHON" -m lerobot_mtdagger.cli run --progress=false \
    --rollout.workers=0 "$@" --output_dir="$OUT/$name"
}
run toy --suite.name=toy --dagger.rounds=2
run state --preset=small --dagger.rounds=1 --training.steps_per_round=100 --rollout.eval_episodes=1 \
  --scheduler.type=gain
run pointcloud --preset=drawers-pointcloud --dagger.rounds=1 --dagger.initial_demos=2 \
  --dagger.budget_per_task=2 --training.steps_per_round=20 --rollout.eval_episodes=1 --suite.num_points=128
run act --suite.name=toy --dagger.rounds=1 --training.steps_per_round=5 --rollout.eval_episodes=1 \
  --policy.type=act --policy.chunk_size=10 --policy.n_action_steps=5 --policy.batch_size=8
echo "four runs in $OUT"
