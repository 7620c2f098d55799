#!/usr/bin/env bash
# The default fast test suite in one process (`-n 0`) and on every core (the default `-n auto`, pytest-
# xdist), one after the other in one run on an otherwise idle machine. Prints the wall and CPU seconds
# of each and the ratio; each suite's summary line says whether it passed. From the repository root:
#   bash benchmarks/bench_test_suite.sh [PYTHON]   # default .venv/bin/python; .venv312/bin/python: 3.12
set -euo pipefail
export MUJOCO_GL=${MUJOCO_GL:-egl}
python=${1:-.venv/bin/python}
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
declare -A wall cpu
for workers in 0 auto; do
  /usr/bin/time -f "%e %U %S" -o "$work/time-$workers" \
    "$python" -m pytest -q -p no:cacheprovider -n "$workers" > "$work/suite-$workers.log" 2>&1 ||
    echo "-n $workers failed: $(tail -n 1 "$work/suite-$workers.log")"
  read -r elapsed user system < <(tail -n 1 "$work/time-$workers")
  wall[$workers]=$elapsed
  cpu[$workers]=$(echo "$user + $system" | bc)
done
echo "$("$python" -V), $(nproc) cores"
echo "| fast suite | wall (s) | CPU (s) | wall / one process |"
echo "|---|---:|---:|---:|"
for workers in 0 auto; do
  printf "| -n %s | %.0f | %.0f | %.2f |\n" "$workers" "${wall[$workers]}" "${cpu[$workers]}" \
    "$(echo "${wall[$workers]} / ${wall[0]}" | bc -l)"
done
for workers in 0 auto; do
  echo "-n $workers: $(tail -n 1 "$work/suite-$workers.log")"
done
