#!/usr/bin/env bash
# Whether one run of this study is done: exit 0 when RECORDS/seed<SEED>/runs-records.tar.gz holds
# METHOD-seed<SEED>'s phase 5 with its evaluation, 1 otherwise. One definition for one_run.sh (which
# skips a done run) and experiments/resume.sh (which gives the study's last run both cores):
#   bash experiments/pixels-matched-eval/run_done.sh METHOD SEED [RECORDS]
set -uo pipefail
RECORDS=${3:-$(cd "$(dirname "$0")" && pwd)/records}
ARCHIVE=$RECORDS/seed$2/runs-records.tar.gz
[ -f "$ARCHIVE" ] && tar xzOf "$ARCHIVE" "./$1-seed$2/policies/round-005/training.json" 2> /dev/null | grep -q '"eval"'
