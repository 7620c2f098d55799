#!/usr/bin/env bash
# From ../main: finishes ../pixels-bc-dev (resumed from its frozen worktree; a finished study is only
# re-reported), saves its records and decision here in ../main, then runs this study from its frozen
# worktree and saves its records. Either study resumes where it stopped; run it again after a stop:
#   nohup bash docs/results/pixels-eval/chain.sh >> outputs/pixels-chain.log 2>&1 &
# The worktrees: ../study-code-pixels-bc at af74c16, ../study-code-pixels-eval at the commit that
# added this folder's run.sh and the memory fix (f33425a), each with .venv and outputs linked to ../main.
set -euo pipefail
MAIN=$PWD
(cd ../study-code-pixels-bc && PYTHONPATH=$PWD bash docs/results/pixels-bc-dev/run.sh)
mkdir -p docs/results/pixels-bc-dev/report
cp -r ../study-code-pixels-bc/docs/results/pixels-bc-dev/report/. docs/results/pixels-bc-dev/report/
bash docs/results/pixels-bc-dev/save_records.sh
cp docs/results/pixels-bc-dev/table.txt ../study-code-pixels-eval/docs/results/pixels-bc-dev/table.txt
(cd ../study-code-pixels-eval && PYTHONPATH=$PWD bash docs/results/pixels-eval/run.sh)
mkdir -p docs/results/pixels-eval/report
cp -r ../study-code-pixels-eval/docs/results/pixels-eval/report/. "$MAIN/docs/results/pixels-eval/report/"
bash docs/results/pixels-eval/save_records.sh
