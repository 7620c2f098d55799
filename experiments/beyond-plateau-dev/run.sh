#!/usr/bin/env bash
# Development seeds (100-102), MT10 state: does DAgger keep rising past the level where one-round BC
# levels off? On the evaluation seeds BC levels off at .92-.93 from about 21 demos per task on MT10
# and MT50, and task need catches up with it at 30-33 demos, where those studies stop. This pilot
# runs task need for 20 DAgger rounds (up to 63 demos per task) and BC at 21, 33, 45 and 63 demos per
# task, to decide whether an evaluation-seed extension past 33 demos is worth its cost. Uniform DAgger
# was added as a control (is it DAgger or the scheduler?) at 00:16 UTC, after need-seed100's first 10
# rounds had been seen; the decision rule below is unchanged.
#
# Settings fixed on 2026-11-25 before any run of it: the `small` preset (the MT10 study's), the
# default protocol, 20 evaluation episodes per task. Decision rule, fixed with them: an
# evaluation-seed extension is proposed if need's mean success over 45-63 demos is above BC's by
# more than 0.02, with need ahead on every seed. Run ONCE; resumable. From the repository root:
#   nohup bash docs/results/beyond-plateau-dev/run.sh > outputs/beyond-plateau-dev.log 2>&1 &
set -euo pipefail
CLI=.venv/bin/lerobot-mtdagger
OUT=outputs/beyond-plateau-dev
"$CLI" compare --methods='[need,bc,uniform]' --seeds='[100,101,102]' --jobs=2 --preset=small --rounds=20 \
  --bc_budgets='[21,33,45,63]' --eval_episodes=20 --progress=false --output_dir="$OUT"
"$CLI" report --compare_dir="$OUT" --levels='[0.8,0.9,0.95]' --output_dir=docs/results/beyond-plateau-dev/report
