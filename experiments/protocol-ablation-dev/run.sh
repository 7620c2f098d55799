#!/usr/bin/env bash
# Protocol ablation on the development seeds (100-102), MT10 state, `small` preset, 10 evaluation
# episodes per task. One `compare` per protocol variant, each changing ONE option from the default
# protocol; every variant resumes where it stopped. Run from the repository root:
#   nohup bash docs/results/protocol-ablation-dev/run.sh > outputs/ablation-dev.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/ablation-dev
COMMON=(--seeds='[100,101,102]' --jobs=2 --eval_episodes=10 --progress=false)

variant() {  # name, methods, extra run options...
  local name=$1 methods=$2
  shift 2
  "$CLI" compare --methods="$methods" --bc_budgets='[12]' "${COMMON[@]}" --output_dir="$OUT/$name" "$@"
  "$CLI" report --compare_dir="$OUT/$name"
}

variant default '[bc,uniform,need,gain]'
variant mixing-step '[uniform,need]' --mixing=step
variant rollout-cap-200 '[uniform,need]' --max_rollout_steps=200
variant normalisation-recompute '[uniform,need]' --normalisation=recompute
variant retrain-epochs '[bc,uniform,need]' --warm_start=false --steps_rule=epochs --epochs=100
variant sampling-balanced '[bc,uniform,need]' --sampling=balanced
# Added 2026-11-22: rollouts cut at twice the expert's length on the same seed.
variant rollout-expert-2x '[uniform,need]' --rollout_expert_multiple=2
# Added 2026-11-22 (last session of the day): the beta schedule, the one protocol option of the
# issue not yet ablated. The learner acts in every DAgger rollout (beta 0), and a slower decay
# (0.5, 0.25, 0 over the 3 rounds instead of 0.5, 0, 0).
variant beta-0 '[uniform,need]' --beta=0
variant beta-decay-0.25 '[uniform,need]' --beta_decay=0.25
# Added 2026-11-22 (same session): train each phase, BC's too, until the loss on held-out episodes
# stops improving (the third training rule; code of commit 7c77eaf, which adds it).
variant plateau '[bc,uniform,need]' --steps_rule=plateau
