#!/usr/bin/env bash
# Development seeds (100-102), MT10 state: the same training search for DAgger as for BC past the
# plateau (#55 item 2). ../bc-past-plateau-dev searched four BC trainings and cosine decay won (+0.032
# over plain BC on the evaluation seeds); need and uniform were only ever run with the plain training.
# A comparison of a searched BC with an unsearched DAgger is not fair to DAgger.
#
# Settings fixed on 2026-11-28 before any run, all ../bc-past-plateau-dev's: the `small` preset, 20
# DAgger rounds (3 initial demos per task, 3 per task per round: 33 / 45 / 63 demos per task after
# rounds 10 / 14 / 20), 20 evaluation episodes per task, development seeds 100-102, the four trainings
#   plain       the default (its need and uniform runs on these seeds are ../beyond-plateau-dev's,
#               `report/results.csv`, the same options; re-run here LAST, seed 100 only, as a check
#               that today's code gives the same curve: if any of its 20 rounds' success differs, the
#               plain row is taken from the re-run seeds and the remaining seeds are run too);
#   balanced    --training.sampling=balanced;
#   cosine      --training.lr_schedule=cosine (each phase's rate decayed to 0 over its steps);
#   plateau     --training.steps_rule=plateau (20% of each task's episodes held out, every 200 steps,
#               patience 5, at most 20 000 steps);
# each applied to every phase of need and of uniform.
# Decision rule (../bc-past-plateau-dev's, applied per method by table.py): the best training of a
# method is the one with the highest 3-seed mean success over 33, 45 and 63 demos per task among those
# whose mean at 63 is not below their mean at 33 by more than 0.01; if none qualifies, the highest
# mean, said so.
# Then, ONCE, on the evaluation seeds 0-4 (../plateau-dagger-training-eval, to be fixed before its
# runs): need and uniform with their chosen training against the best BC (cosine,
# ../beyond-plateau-best-bc). Primary outcome fixed now: need(best training) - best BC in mean success
# over 45-63 demos per task, paired over the 5 seeds, 95% t interval; secondary: uniform(best) - best
# BC, need(best) - uniform(best) on the same window. If the chosen training of a method is plain, its
# evaluation-seed runs are ../beyond-plateau-eval's and are not repeated.
#
# Cost: a 20-round DAgger run took about 20-25 min of one core in ../beyond-plateau-eval; 2 methods x
# 3 trainings x 3 seeds = 18 runs + the plain check, about 7 core-hours at one job (JOBS=1, one core;
# the other core runs ../paper-regime-* ). Resumable: finished runs are skipped, cut-off ones resumed.
# From a frozen worktree at the commit that added this file (experiments/resume.sh makes it):
#   PYTHONPATH=$PWD nohup bash experiments/plateau-dagger-training-dev/run.sh >> outputs/plateau-dagger-training-dev.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/plateau-dagger-training-dev
COMMON=(--methods='[need,uniform]' --seeds='[100,101,102]' --jobs="${JOBS:-1}" --preset=small --dagger.rounds=20
  --rollout.eval_episodes=20 --progress=false)
"$CLI" compare "${COMMON[@]}" --training.lr_schedule=cosine --output_dir="$OUT/cosine"
"$CLI" compare "${COMMON[@]}" --training.sampling=balanced --output_dir="$OUT/balanced"
"$CLI" compare "${COMMON[@]}" --training.steps_rule=plateau --output_dir="$OUT/plateau"
"$CLI" compare --methods='[need,uniform]' --seeds='[100]' --jobs="${JOBS:-1}" --preset=small --dagger.rounds=20 \
  --rollout.eval_episodes=20 --progress=false --output_dir="$OUT/plain-check"
