#!/usr/bin/env bash
# How long a command takes to answer --help or refuse an option or a path, this checkout against a reference
# commit, side by side in one run (median of REPEATS runs each; the ratio is reference / now).
#   bash benchmarks/bench_cli_startup.sh [REFERENCE]   (default: 19e28d3, before the lazy imports)
# Uses this checkout's .venv for both (the reference's code from a temporary worktree).
set -euo pipefail
REFERENCE=${1:-19e28d3}
REPEATS=${REPEATS:-3}
PY=${PY:-$PWD/.venv/bin/python}
TREE=$(mktemp -d)/reference
git worktree add --detach -q "$TREE" "$REFERENCE"
trap 'git worktree remove --force "$TREE"' EXIT

median_seconds() {  # median_seconds DIR ARGS...: median wall time of `python -m lerobot_mtdagger.cli ARGS`
  local dir=$1
  shift
  for _ in $(seq "$REPEATS"); do
    (cd "$dir" && /usr/bin/time -f "%e" "$PY" -m lerobot_mtdagger.cli "$@" > /dev/null 2> /tmp/bench-cli.err || true)
    tail -1 /tmp/bench-cli.err
  done | sort -n | sed -n "$(( (REPEATS + 1) / 2 ))p"
}

printf '| command | %s (s) | now (s) | ratio |\n|---|---:|---:|---:|\n' "$REFERENCE"
for args in "--help" "run --help" "run --preset=nope" "compare --help" "eval --help" "report --help" \
  "verify --help" "run --policy.type=act --help" "verify --experiment_dir=/no/such/run" \
  "merge --experiment_dir=/no/such/run --output=/no/such/merged" "eval --policy_path=/no/such/policy"; do
  # shellcheck disable=SC2086  # the command's words
  before=$(median_seconds "$TREE" $args)
  # shellcheck disable=SC2086
  now=$(median_seconds "$PWD" $args)
  ratio=$(awk -v a="$before" -v b="$now" 'BEGIN { printf "%.1f", a / b }')
  printf '| `%s` | %s | %s | %s |\n' "$args" "$before" "$now" "$ratio"
done
