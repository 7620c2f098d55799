#!/usr/bin/env bash
# Starts (or, after a stop, restarts) the studies still running, every step resumable, one job per
# core: each study from its own frozen worktree, pinned to its core. Works on a new checkout (no
# outputs/, no worktrees): it makes the worktrees it needs. From ../main, once the README's setup
# command has made .venv, from a copy (bash reads a script as it runs it, so editing this file would
# change a running one):
#   mkdir -p outputs && cp experiments/resume.sh outputs/resume-running.sh
#   nohup bash outputs/resume-running.sh >> outputs/resume.log 2>&1 &
# To change the queue while studies run: stop the earlier copy's chains (its bash processes, not the
# runs: `pkill -f outputs/resume-running.sh` before copying), then start the new copy; a run still
# going is refused by its lock (on either core), and that chain goes on to its next run.
#
# A machine may or may not keep outputs/ between sessions: the session of 2026-11-29 06:55 came as a new
# checkout without it (two cut runs lost), the one of 10:45 found outputs/, .venv and the worktrees as
# the one before left them. So the queue holds only runs still to do, each saves its records into the
# study's records/ (commit them) when it ends, and `compare` resumes a cut run from its last committed
# phase when outputs/ is still there. Complete studies are not in the queue (their records and READMEs
# hold their results): paper-regime-eval, paper-regime-pertask-dev, paper-regime-training-dev,
# plateau-dagger-training-dev, plateau-dagger-eval; drawers-preset-dev stopped (its README).
# Every run of the queue below is done (pixels-matched-eval complete 2026-11-30 19:30): run now, the script
# skips each and starts nothing; it stays as the record of how the studies were carried out.
# Queue (2026-11-29): pixels-dagger-epochs-dev's runs not yet in its records (its one_run.sh: a run whose
# records hold phase 5 is skipped; all 6 are in since 2026-11-29 19:55). Once all 6 are in its records,
# its report.sh (the reports and table that pixels-matched-eval's gate reads, DEV below). Then
# pixels-matched-eval one run at a time (its one_run.sh: run.sh's gate first; it runs because its
# gate-deviation.md says why, though the development rule proposed no rerun; each run as long as an
# epochs run), each run on both cores with 2 torch threads (decided 2026-11-30 11:00; until then one
# run per core, the last on both): on two cores a pixel phase went 1.8-1.9x faster than on one core beside
# another run (../pixels-dagger-epochs-dev, "How it ran"), so the study's pace is nearly the same, and a
# run ends inside one session on either machine (about 1 hour on an AVX-512 one, 1.7 on an AVX2 one),
# where two runs side by side, 2.75 and 4 hours, end together or not at all when a machine keeps no
# outputs/ (threads change floating-point sums only). A run cut by a stop resumes first.
# With SESSION_END set (a UTC time, e.g. SESSION_END=09:50), a run that would not end before it is put
# off: the chain runs the ones that fit first, then the ones it put off, in order (a stop cuts them;
# `compare` resumes them if outputs/ is kept, and nothing else would use the core meanwhile). A run is
# refused while another chain runs it (a lock per run, whatever the core). How long a run takes on one
# core, beside another pixel run, depends on the machine (FIXED_MIN and EPOCHS_MIN below, for a run
# from its start):
#   - with AVX-512 (the machine of 2026-11-28): an epochs run took 147 min alone (seed 100's records),
#     a fixed one about 60 (../pixels-eval);
#   - with AVX2 only (2026-11-29): a fixed phase took about 23 min (1 500 steps 223-230 s, a 20-episode
#     evaluation 710-750 s, 1.7x and 1.6x the other machine), so a fixed run takes about 2.3 hours and
#     an epochs run about 4 (estimated: seed 100's phases at those ratios): longer than a session.
# BOTH_MIN: an epochs run on both cores: 57 minutes for phases 1-5 of need seed 0 on the AVX-512
# machine (2026-11-30, docs/benchmarks.md), about 1.7x that on the AVX2 one (estimated).
set -uo pipefail

PIXELS_COMMIT=${PIXELS_COMMIT:-a10a67e}  # the commit that added pixels-dagger-epochs-dev
PIXELS_EVAL_COMMIT=${PIXELS_EVAL_COMMIT:-51623d0}  # pixels-matched-eval's code: its README, "Round 0 shared"
MATCHED_TREE=${MATCHED_TREE:-study-code-pixels-matched-progress}  # its worktree ("Phases resume mid-way")
ONE_RUN=${ONE_RUN:-$PWD/experiments/pixels-dagger-epochs-dev/one_run.sh}  # read as it runs: do not edit meanwhile
MATCHED_RUN=${MATCHED_RUN:-$PWD/experiments/pixels-matched-eval/one_run.sh}  # read as it runs: do not edit meanwhile
DEV=${DEV:-$PWD/experiments/pixels-dagger-epochs-dev}  # its records/ and, once report.sh has run, report/
if grep -qw avx512f /proc/cpuinfo; then FIXED_MIN=${FIXED_MIN:-75} EPOCHS_MIN=${EPOCHS_MIN:-165} BOTH_MIN=${BOTH_MIN:-65}
else FIXED_MIN=${FIXED_MIN:-145} EPOCHS_MIN=${EPOCHS_MIN:-250} BOTH_MIN=${BOTH_MIN:-110}; fi  # minutes a run takes (above)

log() { echo "$(date -u +%FT%H:%M:%S) $*"; }

worktree() {  # worktree NAME COMMIT: ../NAME frozen at COMMIT, with this checkout's .venv and outputs/
  # One at a time (both cores' chains may ask for the same new worktree at once; git would refuse one).
  # A ../NAME at another commit is refused: a study's code changes only under a new worktree name.
  (
    flock 9
    if [ ! -d "../$1" ]; then
      git worktree prune
      git worktree add --detach "../$1" "$2" || exit 1
    fi
    local at
    at=$(git -C "../$1" rev-parse HEAD)
    if [ "$at" != "$(git rev-parse "$2^{commit}")" ]; then
      log "../$1 is at ${at:0:7}, not $2: remove it (git worktree remove ../$1) or freeze $2 under another name"
      exit 1
    fi
    ln -sf ../main/.venv "../$1/.venv"
    ln -sfn ../main/outputs "../$1/outputs"
  ) 9> outputs/.worktree.lock
}

run_lock() {  # run_lock NAME [ARGS]: the lock file of one run (study holds it while the run goes)
  local name=$1 IFS=-
  shift
  echo "outputs/.$name-$*.lock"  # outputs/.NAME-ARG1-ARG2.lock
}

study() {  # study NAME WORKTREE COMMIT CORE SCRIPT [ARGS]: SCRIPT ARGS in ../WORKTREE (at COMMIT), on CORE
  # A second process for the same NAME and ARGS, on any core, is refused by a lock. Returns the script's
  # status.
  local name=$1 tree=$2 commit=$3 core=$4 script=$5 part status lock
  shift 5
  part=" ($*)"
  worktree "$tree" "$commit" || { log "cannot make ../$tree"; return 1; }
  exec {lock}> "$(run_lock "$name" "$@")"
  flock -n "$lock" || { log "$name$part is already running: stop it first"; exec {lock}>&-; return 1; }
  log "$name$part on core $core"
  (cd "../$tree" && PYTHONPATH=$PWD JOBS=1 taskset -c "$core" bash "$script" "$@") \
    >> "outputs/$name.log" 2>&1
  status=$?
  exec {lock}>&-
  log "$name$part ended with status $status"
  return "$status"
}

fits() {  # fits MINUTES: whether a step of about MINUTES ends before SESSION_END (always, unset)
  # SESSION_END is a time of day: more than 12 hours before now, it is tomorrow's (a session past midnight).
  [ -z "${SESSION_END:-}" ] && return 0
  local end now
  end=$(date -u -d "$SESSION_END" +%s) || return 1
  now=$(date -u +%s)
  [ "$end" -lt $((now - 43200)) ] && end=$((end + 86400))
  [ $((now + 60 * $1)) -le "$end" ] || { log "put off: about $1 min would pass SESSION_END $SESSION_END"; return 1; }
}

PUT_OFF=()  # the steps this chain put off (each chain is a subshell with its own), run by run_put_off

later_if_long() {  # later_if_long MINUTES STEP [ARGS]: false, and STEP ARGS kept for later, if it does not fit
  fits "$1" && return 0
  shift
  PUT_OFF+=("$*")
  return 1
}

run_put_off() {  # the steps this chain put off, in their order, now that nothing that fits is left
  local step
  for step in "${PUT_OFF[@]}"; do
    log "starting the step put off: $step (a stop cuts it; compare resumes it if outputs/ is kept)"
    $step  # split into the function and its arguments (no argument holds a space)
  done
  PUT_OFF=()
}

dev_run() {  # dev_run CORE ARM SEED MINUTES: dev_start, or put off if a run of MINUTES would not fit
  later_if_long "$4" dev_start "$1" "$2" "$3" || return 1
  dev_start "$1" "$2" "$3"
}

dev_start() {  # dev_start CORE ARM SEED: one pixels-dagger-epochs-dev run (its one_run.sh) on CORE
  OMP_NUM_THREADS=1 study pixels-dagger-epochs-dev study-code-pixels-epochs "$PIXELS_COMMIT" "$1" "$ONE_RUN" "$2" "$3"
}

dev_report() {  # pixels-dagger-epochs-dev's reports and table (report.sh), once all 6 runs are in its records
  # A run that another chain is running is waited for (its lock), so that the chain that ends first
  # goes on to pixels-matched-eval, whose gate reads the report, instead of finding it missing.
  local arm seed record lock
  for arm in epochs fixed; do
    for seed in 100 101 102; do
      record=$DEV/records/$arm/uniform-seed$seed/policies/round-005/training.json
      lock=$(run_lock pixels-dagger-epochs-dev "$arm" "$seed")
      if ! grep -qs '"eval"' "$record" && [ -f "$lock" ] && ! flock -n "$lock" true; then
        log "pixels-dagger-epochs-dev: waiting for $arm seed $seed, which another chain is running"
        flock "$lock" true
      fi
      grep -qs '"eval"' "$record" || { log "pixels-dagger-epochs-dev: $arm seed $seed not in its records yet"; return 1; }
    done
  done
  log "pixels-dagger-epochs-dev: every run done; report.sh"
  (flock 9 && bash experiments/pixels-dagger-epochs-dev/report.sh) 9> outputs/.dev-report.lock \
    >> outputs/pixels-dagger-epochs-dev.log 2>&1
}

matched_run() {  # matched_run METHOD SEED: matched_start, or put off if it would not fit
  later_if_long "$BOTH_MIN" matched_start "$1" "$2" || return 1
  matched_start "$1" "$2"
}

matched_start() {  # matched_start METHOD SEED: one pixels-matched-eval run (its one_run.sh) on both cores
  OMP_NUM_THREADS=2 DEV=$DEV study pixels-matched-eval "$MATCHED_TREE" "$PIXELS_EVAL_COMMIT" 0,1 \
    "$MATCHED_RUN" "$1" "$2"
}

if [ "${BASH_SOURCE[0]}" != "$0" ]; then return 0; fi  # sourced (its tests): functions only

mkdir -p outputs
(dev_run 0 epochs 101 "$EPOCHS_MIN"
  dev_run 0 fixed 100 "$FIXED_MIN"
  dev_run 0 fixed 101 "$FIXED_MIN"
  dev_report || PUT_OFF+=(dev_report)
  run_put_off) &
(dev_run 1 epochs 102 "$EPOCHS_MIN"
  dev_run 1 fixed 102 "$FIXED_MIN"
  dev_report || PUT_OFF+=(dev_report)
  run_put_off) &
wait
# Seeds 0 and 1 first (uniform's are done; a run the last stop cut resumes first), then seed 2 with
# uniform first, whose round 0 need and gain copy.
for run in "uniform 0" "uniform 1" "need 0" "need 1" "gain 0" "gain 1" "uniform 2" "need 2" "gain 2"; do
  matched_run $run  # METHOD SEED
done
run_put_off
