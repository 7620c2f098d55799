#!/usr/bin/env bash
# A second process for this study, on the other core: run.sh's two `compare` commands (the same options,
# checked by experiments/lab/tests/test_second_core.py) in the other order, `fixed` first. compare
# shares a folder's runs between processes with the same options (each skips the runs another has
# finished or is writing), so with run.sh on one core and this on the other the study's runs go two at
# a time. A compare that skipped a run the other process was writing ends with an error; this goes on
# to the next arm (no `set -e`), and run.sh's last compare writes the tables once every run is done.
# Memory: two pixel runs at once peak at about 15-20 GB (../pixels-eval ran so on two cores).
# From the study's frozen worktree, as experiments/resume.sh starts it:
#   (cd ../study-code-pixels-epochs && OMP_NUM_THREADS=1 taskset -c 0 bash ../main/experiments/pixels-dagger-epochs-dev/second_core.sh)
set -uo pipefail
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
OUT=outputs/pixels-dagger-epochs-dev
COMMON=(--methods='[uniform]' --seeds='[100,101,102]' --jobs=1 --preset=metaworld-pixels
  --rollout.eval_episodes=20 --progress=false)
status=0
"$CLI" compare "${COMMON[@]}" --output_dir="$OUT/fixed" || status=$?
"$CLI" compare "${COMMON[@]}" --training.steps_rule=epochs --training.epochs=10 --output_dir="$OUT/epochs" || status=$?
echo "$(date -u +%H:%M:%S) done (status $status)"
exit "$status"
