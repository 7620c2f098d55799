#!/usr/bin/env bash
# Saves a study's compare folders: each one's results table and its runs' records (config, round and
# phase records; no frames or weights) compacted into one byte-stable archive, runs-records.tar.gz.
#   bash scripts/save_compare_records.sh STUDY   (outputs/STUDY/<folder>/ -> experiments/STUDY/records/<folder>/)
# Read the records back with: tar xzf experiments/STUDY/records/<folder>/runs-records.tar.gz -C <somewhere>
# Runs an earlier save archived and outputs/ no longer holds (a machine that kept no outputs/ between
# sessions) stay in the archive; a run outputs/ holds replaces its archived records whole. When the
# archive then holds runs the compare folder did not run, that folder's results.csv would not show them:
# it is not saved (an earlier one is removed), and `lerobot-mtdagger report --records=<the folder>`
# makes the table of every archived run. The toolkit's `records --action=save_compares`, kept under
# this name for the studies' scripts (PYTHON: the interpreter with the package, default .venv/bin/python).
set -euo pipefail
STUDY=${1:?give the study, e.g. plateau-dagger-training-dev}
exec "${PYTHON:-$(dirname "$0")/../.venv/bin/python}" -m lerobot_mtdagger.cli records --action=save_compares \
  --source="outputs/$STUDY" --dest="experiments/$STUDY/records"
