#!/usr/bin/env bash
# The paper's regime, step 3 (issue item 6): BC, Uniform DAgger, need, need_raw and gain on the
# imperfect-expert MT50 of ../paper-regime-pertask-dev, on EVALUATION seeds 0-2. Fixed 2026-11-28,
# before any run of it and before ../paper-regime-training-dev (the training search on development
# seeds 100-101) had any DAgger result. Run once; nothing here is tuned on seeds 0-2.
#
# Setting: ../paper-regime-pertask-dev's (its kept.txt: the 43 kept tasks with their own noise scales),
# correlation 0.9, noise seed 100, labels = the executed noisy actions, `--preset=metaworld-state`
# (the paper's budgets: 3 initial demos per task and 3 per task per round), 20 evaluation episodes per
# task after every phase.
# Settings read from the development study before the first run (`table.py --settings`, rules written
# here and in table.py now):
#   - each arm's training: ../paper-regime-training-dev's decision for bc, uniform and need; need_raw
#     and gain take need's (they were not searched, for cost);
#   - rounds ("enough to reach 80%"): 9 (30 demos per task) if need's mean success at 30 demos over the
#     two development seeds under its chosen training is >= 0.80, else 12 (39 demos per task);
#   - BC budgets: 6, 12, 18, 24 and 30 demos per task, and 39 when the rounds are 12 (every second
#     DAgger budget, for cost; BC at 3 demos is DAgger's phase 0, the same run);
#   - the hardest tasks: the 5 with the lowest mean success of BC at 30 demos (chosen training) over
#     development seeds 100-101; written to outputs/paper-regime-eval/settings.txt before any run.
# Primary outcome (table.py): need - uniform in mean success over the BC budgets (DAgger: its phases at
# those budgets), paired over the 3 seeds with a 95% t interval. Claim "the performance-aware schedule
# saves expert demonstrations over uniform DAgger": reproduced if the interval is above 0, reversed if
# below, inconclusive otherwise (with 3 seeds the design resolves about +-0.03). Co-primary: demos per
# task to reach 0.80 mean success, per arm and seed (linear between evaluated budgets; a curve that
# never reaches it is censored at its last budget and shown as such), need - uniform and need - BC
# paired over the seeds where both reach it. Secondary: need_raw and gain - uniform, need - BC and
# uniform - BC in mean success over the same budgets; the hardest-task analysis: need - uniform and
# need - BC in mean success over the budgets on the 5 hardest tasks (mean over those tasks), paired.
# Every phase's passes over each task's frames are in its training.json (table.py shows them).
# Cost (measured: ../paper-regime-pertask-dev's BC at 6 demos 37 s collecting, 187 s training 6 000
# steps, 269 s evaluating 20 episodes x 43 tasks): a 9-round DAgger run about 65 min, 12 rounds about
# 90 min; BC at the 5-6 budgets 75-100 min; about 6-7.5 core-hours per seed, 17-22 core-hours in all.
# Order: seed 0 (every arm), then 1, then 2; `SEEDS="0 1 2"` by default (two cores: one process per
# seed subset, e.g. SEEDS="0 2" on core 0 and SEEDS=1 on core 1; they write different folders).
# From a frozen worktree of the commit that added this file (experiments/resume.sh makes it):
#   PYTHONPATH=$PWD nohup bash experiments/paper-regime-eval/run.sh >> outputs/paper-regime-eval.log 2>&1 &
# Resumable: finished runs are skipped, cut-off ones resumed (compare).
set -euo pipefail
CLI=${CLI:-.venv/bin/lerobot-mtdagger}
PY=${PY:-.venv/bin/python}
OUT=outputs/paper-regime-eval
DEV=outputs/paper-regime-training-dev
CHECK=outputs/paper-regime-pertask-dev
HERE=$(dirname "$0")
log() { echo "$(date -u +%FT%H:%M:%S) $*"; }
mkdir -p "$OUT"
if [ ! -s "$OUT/settings.txt" ]; then
  if ! PYTHONPATH=experiments:${PYTHONPATH:-} "$PY" "$HERE/table.py" --settings "$DEV" "$CHECK" > "$OUT/settings.tmp"; then
    log "the development study has not decided every setting yet (table.py --settings $DEV): nothing to run"
    cat "$OUT/settings.tmp"; rm -f "$OUT/settings.tmp"; exit 1
  fi
  mv "$OUT/settings.tmp" "$OUT/settings.txt"
fi
setting() { sed -n "s/^$1: //p" "$OUT/settings.txt"; }
tasks=$(sed -n 's/^tasks: //p' "$CHECK/kept.txt")
map=$(sed -n 's/^map: //p' "$CHECK/kept.txt")
rounds=$(setting rounds)
SETTING=(--jobs="${JOBS:-1}" --preset=metaworld-state --dagger.rounds="$rounds" --suite.tasks="[$tasks]"
  --expert.noise_by_task="$map" --expert.noise_correlation=0.9 --expert.noise_seed=100
  --expert.labels=noisy --rollout.eval_episodes=20 --progress=false)
log "settings: $(tr '\n' ';' < "$OUT/settings.txt" | cut -c1-300)"
for seed in ${SEEDS:-0 1 2}; do
  for training in plain cosine; do
    methods=$(setting "arms $training")
    [ -n "$methods" ] || continue
    options=()
    [ "$training" = cosine ] && options+=(--training.lr_schedule=cosine)
    case ",$methods," in *,bc,*) options+=(--bc_budgets="[$(setting "bc budgets")]") ;; esac
    log "$training ($methods), seed $seed"
    "$CLI" compare "${SETTING[@]}" "${options[@]}" --methods="[$methods]" --seeds="[$seed]" \
      --output_dir="$OUT/$training-seed$seed"
  done
done
log "done"
