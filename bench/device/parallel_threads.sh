#!/usr/bin/env bash
# Runs on the lent device machine (repository root, carry ['.dev']): the speed-up of a parallel
# scheme's participants on threads in one process, on a quiet machine, restricted to 2
# of its cores (taskset) and on 4. The bundle: bench/device/pack.sh --threads-only here.
# The steel compaction case, 1000 windows, the granules about as costly as the plate; per core set
# and --threads: explicit-serial, explicit-parallel one after the other (concurrent: false) and
# on threads (concurrent: true; again with OMP_WAIT_POLICY=PASSIVE: no spinning), alternated RUNS
# times. Prints each run's summary line and its
# process time (wall, user, sys) to $OUT/parallel_threads.log.
set -uo pipefail
runs=${RUNS:-5}
source "$(dirname "$0")/bundle.sh"
open_log parallel_threads.log
unpack_bundle || exit 1
export PARTITA_LOG_LEVEL=info
say "$(nproc) processors; $(grep -m1 'model name' /proc/cpuinfo); $(uptime)"
common=(--set time.end=0.01 --set output.every=1 --set coupling.on_energy_created=warn
        --set participants.granules.time_step_fraction=0.12)
one() {  # cpus threads scheme concurrent [env...]
  local TIMEFORMAT="process %R s wall, %U s user, %S s sys"
  { time env "${@:5}" taskset -c "$1" "$dev/bin/partita" run cases/uniaxial_compaction/steel.yaml -o /tmp/pt \
      --threads "$2" "${common[@]}" --set coupling.scheme="$3" --set coupling.concurrent="$4" \
      2>&1 | grep -o 'summary: .*core [0-9.]* s'; } 2>&1 | tr '\n' ' '
  echo
}
for set in "0,1 2" "0,1 1" "0-3 4"; do
  read -r cpus threads <<< "$set"
  say ""
  say "== cores $cpus, --threads $threads ($(date -u +%T))"
  for i in $(seq "$runs"); do
    say "serial   $(one "$cpus" "$threads" explicit-serial false)"
    say "par 1x1  $(one "$cpus" "$threads" explicit-parallel false)"
    say "threads  $(one "$cpus" "$threads" explicit-parallel true)"
    say "thr pass $(one "$cpus" "$threads" explicit-parallel true OMP_WAIT_POLICY=PASSIVE)"
  done
done
say "done $(date -u +%T)"
