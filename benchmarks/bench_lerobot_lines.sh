#!/usr/bin/env bash
# The two LeRobot lines side by side, in one run on an otherwise idle machine: the README's main command
# (`lerobot-mtdagger run`, the small preset) and the default fast test suite, each on Python 3.11
# (LeRobot 0.4.4, .venv) and Python 3.12 (LeRobot 0.6.1, .venv312), one after the other. Prints the wall
# times and the ratio 3.12 / 3.11. Needs both environments (the README's test command with each
# interpreter; .ci/run makes both). From the repository root:
#   bash benchmarks/bench_lerobot_lines.sh [--no-tests]
set -euo pipefail
export MUJOCO_GL=${MUJOCO_GL:-egl}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
declare -A seconds
timed() {  # timed KEY COMMAND...: wall seconds of COMMAND into seconds[KEY]; its output into $work/KEY.log
  local key=$1
  shift
  local start
  start=$(date +%s.%N)
  "$@" > "$work/$key.log" 2>&1 || echo "$key failed (status $?): $(tail -n 1 "$work/$key.log")"
  seconds[$key]=$(echo "$(date +%s.%N) - $start" | bc)
}
for line in .venv .venv312; do
  timed "run$line" "$line/bin/lerobot-mtdagger" run --output_dir="$work/run$line" --progress=false
done
if [ "${1:-}" != "--no-tests" ]; then
  for line in .venv .venv312; do
    timed "tests$line" "$line/bin/python" -m pytest -q -p no:cacheprovider
  done
fi
echo "| what | Python 3.11, LeRobot 0.4.4 (s) | Python 3.12, LeRobot 0.6.1 (s) | 3.12 / 3.11 |"
echo "|---|---:|---:|---:|"
for what in run tests; do
  [ -n "${seconds[$what.venv]:-}" ] || continue
  a=${seconds[$what.venv]}
  b=${seconds[$what.venv312]}
  printf "| %s | %.0f | %.0f | %.2f |\n" "$what" "$a" "$b" "$(echo "$b / $a" | bc -l)"
done
for line in .venv .venv312; do
  [ -f "$work/tests$line.log" ] && echo "$line tests: $(tail -n 1 "$work/tests$line.log")"
  grep "^round" "$work/run$line.log" | tail -n 1 | sed "s/^/$line run, last round: /" | cut -c1-150
done
