#!/usr/bin/env bash
# Saves the study's results tables and runs' records (one archive per compare folder), from ../main:
#   bash experiments/plateau-dagger-training-dev/save_records.sh
exec bash scripts/save_compare_records.sh plateau-dagger-training-dev
