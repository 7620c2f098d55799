#!/usr/bin/env bash
# One run of this study: run.sh's compare for ARM (epochs or fixed) with the same options (checked by
# experiments/lab/tests/test_one_run.py), on SEED only; then its records are saved into this folder's
# records/ (save_records.sh). A run whose records already hold its last phase (5) with its evaluation
# is skipped, so the queue names the runs still to do. A machine may or may not keep outputs/ between
# sessions; where it does, `compare` resumes a run a stop cut from its last committed phase. On one core
# beside another pixel run: fixed about 1-2 hours, epochs about 2.5 (AVX-512) to 4 (AVX2) hours.
# From the study's frozen worktree, as experiments/resume.sh starts it:
#   (cd ../study-code-pixels-epochs && OMP_NUM_THREADS=1 PYTHONPATH=$PWD taskset -c 0 \
#     bash ../main/experiments/pixels-dagger-epochs-dev/one_run.sh fixed 100)
set -euo pipefail
ARM=$1
SEED=$2
HERE=$(cd "$(dirname "$0")" && pwd)
MAIN=$(cd "$HERE/../.." && pwd)
LAST_RECORD="$HERE/records/$ARM/uniform-seed$SEED/policies/round-005/training.json"
if [ -f "$LAST_RECORD" ] && grep -q '"eval"' "$LAST_RECORD"; then
  echo "$(date -u +%H:%M:%S) $ARM seed $SEED: done (its records hold phase 5), skipped"
  exit 0
fi
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
OUT=outputs/pixels-dagger-epochs-dev
COMMON=(--methods='[uniform]' --seeds="[$SEED]" --jobs=1 --preset=metaworld-pixels
  --rollout.eval_episodes=20 --progress=false)
case "$ARM" in
  epochs) "$CLI" compare "${COMMON[@]}" --training.steps_rule=epochs --training.epochs=10 --output_dir="$OUT/epochs" ;;
  fixed) "$CLI" compare "${COMMON[@]}" --output_dir="$OUT/fixed" ;;
  *) echo "ARM must be epochs or fixed, got '$ARM'" >&2; exit 2 ;;
esac
(cd "$MAIN" && bash experiments/pixels-dagger-epochs-dev/save_records.sh)
echo "$(date -u +%H:%M:%S) $ARM seed $SEED done; records saved"
