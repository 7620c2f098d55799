#!/usr/bin/env bash
# A two-node Ray cluster started by hand on this machine (`ray start --head`, then a second
# `ray start --address=...` with its own CPUs), a small point-cloud drawer run whose two env workers
# are Ray actors on it, and the same run with two local (forked) workers. Prints where each actor ran
# (its node id), both wall times, and compares the two experiments round by round: they must be equal.
#
# Run from the repository root: bash benchmarks/ray_two_nodes.sh   (PORT=6390 OUT=outputs/ray-two-nodes)
# It stops only the cluster it started (its own temp dir), on exit or on error.
set -euo pipefail
RAY=.venv/bin/ray
CLI=.venv/bin/lerobot-mtdagger
PORT=${PORT:-6390}
OUT=${OUT:-outputs/ray-two-nodes}
TEMP=$(mktemp -d /tmp/ray-two-nodes.XXXXXX)
ADDRESS=127.0.0.1:$PORT
export RAY_worker_niceness=0 RAY_AUTH_MODE=disabled  # the actors are the work; no token on one machine

stop_cluster() { RAY_TMPDIR=$TEMP "$RAY" stop --force > /dev/null 2>&1 || true; }
trap stop_cluster EXIT

"$RAY" start --head --node-ip-address=127.0.0.1 --port="$PORT" --num-cpus=1 --temp-dir="$TEMP" \
  --include-dashboard=false --disable-usage-stats > "$TEMP/head.log"
"$RAY" start --address="$ADDRESS" --node-ip-address=127.0.0.1 --num-cpus=1 \
  --disable-usage-stats > "$TEMP/worker.log"
for _ in $(seq 60); do  # the second node registers a few seconds after its `ray start` returns
  [ "$("$RAY" status --address="$ADDRESS" | grep -c '^ 1 node_')" -ge 2 ] && break
  sleep 1
done
"$RAY" status --address="$ADDRESS" | sed -n '/Node status/,/Pending/p'

rm -rf "$OUT"
RUN=(run --suite.name=drawers --suite.obs_mode=pointcloud --suite.num_points=512
  "--suite.tasks=[drawer-bar-wide,drawer-knob-large,drawer-lip-wide]" --dagger.rounds=1
  --dagger.initial_demos=2 --dagger.budget_per_task=2 --training.steps_per_round=100
  --policy.batch_size=64 --rollout.eval_episodes=2 --rollout.workers=2 --progress=false --seed=0)

start=$(date +%s.%N)
"$CLI" "${RUN[@]}" --rollout.worker_backend=ray --rollout.ray_address="$ADDRESS" --output_dir="$OUT/ray"
ray_s=$(echo "$(date +%s.%N) - $start" | bc)
start=$(date +%s.%N)
"$CLI" "${RUN[@]}" --output_dir="$OUT/local"
local_s=$(echo "$(date +%s.%N) - $start" | bc)

echo "actors:"
grep -h "env worker actors" "$OUT/ray/run.log" | sed 's/.*INFO [^:]*: /  /'
printf 'wall time: ray (2 nodes) %.1f s, local workers %.1f s, local/ray %.2fx\n' "$ray_s" "$local_s" \
  "$(echo "$local_s / $ray_s" | bc -l)"
.venv/bin/python scripts/compare_experiments.py "$OUT/local" "$OUT/ray" \
  --ignore-config rollout.worker_backend rollout.ray_address
