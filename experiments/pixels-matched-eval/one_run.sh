#!/usr/bin/env bash
# One run of this study: run.sh's gate, then run.sh's compare for METHOD (uniform, need or gain) on SEED
# only (the same options, checked by experiments/lab/tests/test_pixels_matched_one_run.py), then the
# study's records saved (save_records.sh, which keeps the runs an earlier session archived). A machine
# may not keep outputs/ between sessions, and a seed's compare of three epochs runs (about 7.5 hours on
# an AVX-512 machine) outlasts a session, so the queue gives one run at a time (about 2.5 hours there,
# 4 on an AVX2 one; compare resumes a cut run if outputs/ is kept); a run whose archived records hold
# its phase 5 with its evaluation is skipped.
# The gate is run.sh's own (run with no seed: it decides, or reads decision.txt, and runs nothing):
# nothing runs unless its decision.txt says `run:`, or says the switch with the rerun not proposed while
# gate-deviation.md (OVERRIDE) exists: that file says why the study runs then (decided after the
# development study's result, before any run of this study). Give the development study's committed records and
# report as DEV (run.sh's option), as experiments/resume.sh does.
# From the study's frozen worktree, as experiments/resume.sh starts it:
#   (cd ../study-code-pixels-matched-progress && OMP_NUM_THREADS=1 PYTHONPATH=$PWD DEV=../main/experiments/pixels-dagger-epochs-dev \
#     taskset -c 0 bash ../main/experiments/pixels-matched-eval/one_run.sh need 0)
set -euo pipefail
METHOD=$1
SEED=$2
HERE=$(cd "$(dirname "$0")" && pwd)
MAIN=$(cd "$HERE/../.." && pwd)
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
PY=${PY:-.venv/bin/python}
OUT=${OUT:-outputs/pixels-matched-eval}
RECORDS=${RECORDS:-$HERE/records}
SAVE=${SAVE:-bash experiments/pixels-matched-eval/save_records.sh}
OVERRIDE=${OVERRIDE:-$HERE/gate-deviation.md}  # why the study runs though the gate proposes no rerun
log() { echo "$(date -u +%FT%H:%M:%S) $*"; }
case "$METHOD" in
  uniform | need | gain) ;;
  *) echo "METHOD must be uniform, need or gain, got '$METHOD'" >&2; exit 2 ;;
esac
RUN=$METHOD-seed$SEED
if bash "$HERE/run_done.sh" "$METHOD" "$SEED" "$RECORDS"; then
  log "$RUN: done (its archived records hold phase 5), skipped"
  exit 0
fi
SEEDS=" " bash experiments/pixels-matched-eval/run.sh  # the gate only (no seed to run)
gate=$(PYTHONPATH=experiments:${PYTHONPATH:-} "$PY" experiments/pixels-matched-eval/table.py --gate "$OUT/decision.txt")
case "$gate" in
  run:*) ;;
  "not run:"*"a pixels-eval rerun is not proposed"*)  # the switch, the rerun not proposed: the deviation
    [ -f "$OVERRIDE" ] || { log "$RUN not run: $gate"; exit 0; }
    log "$RUN runs despite the gate's answer ($gate), as $OVERRIDE says why" ;;
  *) log "$RUN not run: $gate"; exit 0 ;;
esac
log "$RUN with 10 passes per phase"
"$CLI" compare --methods="[$METHOD]" --seeds="[$SEED]" --jobs="${JOBS:-1}" \
  --preset=metaworld-pixels --rollout.eval_episodes=20 --progress=false \
  --training.steps_rule=epochs --training.epochs=10 --output_dir="$OUT/seed$SEED"
(cd "$MAIN" && $SAVE)
log "$RUN done; records saved"
