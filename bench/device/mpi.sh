#!/usr/bin/env bash
# Runs on the lent device machine (repository root, carry ['.dev']): what the MPI exchange costs
# on a quiet machine (aim: under 5 % of the steel case's wall time) and what explicit-parallel
# in two processes gains. The bundle: bench/device/pack.sh here, from a build with MPI (it then
# carries OpenMPI: the device has none). bench_mpi (bench/mpi/) on the steel compaction case,
# 1000 windows, RUNS runs each (default 5), one process per participant:
#   1. cores 0,1 (taskset), --threads 1 per process: the figures of bench/README.md's table;
#   2. cores 0-3, --threads 1: the same with a core to spare for each process's helpers;
#   3. cores 0,1, --threads 1, the granules about as costly as the plate (time_step_fraction
#      0.12): the parallel scheme's speed-up (aim above 1.6x on 2 cores);
#   4. cores 0-3, --threads 2 per process.
# Everything goes to $OUT/mpi.log (or ./mpi.log without $OUT). About 2 minutes on a quiet machine
# (4.5 on this loaded 2-core VM).
set -uo pipefail
runs=${RUNS:-5}
source "$(dirname "$0")/bundle.sh"
open_log mpi.log
unpack_bundle || exit 1
use_bundled_mpi || { say "the bundle has no OpenMPI: pack it from a build with MPI"; exit 1; }
[[ -f $dev/bin/bench_mpi ]] || { say "the bundle has no bench_mpi"; exit 1; }
case=$PWD/cases/uniaxial_compaction/steel.yaml
# bench_mpi runs the app and the case at the paths of the build it was configured in
sed -e "s|^PARTITA = .*|PARTITA = \"$dev/bin/partita\"|" -e "s|^CASE = .*|CASE = \"$case\"|" \
  "$dev/bin/bench_mpi" > "$dev/bin/bench_mpi.py"

say "$(nproc) processors; $(grep -m1 'model name' /proc/cpuinfo); $(uptime)"
say "mpirun: $(command -v mpirun) ($(ompi_info --version 2>&1 | head -1))"
say "python: $(command -v python3) $(python3 --version 2>&1)"
# OpenMPI's shared-memory transport copies large messages with process_vm_readv (CMA), which a
# container may forbid: a short two-process run first, and without single copies if it fails
probe() {
  timeout 60 mpirun --oversubscribe --bind-to none \
    -n 1 "$dev/bin/partita" run "$case" -o /tmp/mpi-probe --set time.end=0.0005 --participant plate : \
    -n 1 "$dev/bin/partita" run "$case" -o /tmp/mpi-probe --set time.end=0.0005 --participant granules \
    > /tmp/mpi-probe.log 2>&1
}
if probe; then
  say "probe: two processes ran (OpenMPI's defaults)"
else
  say "probe failed (rc $?):"; tail -15 /tmp/mpi-probe.log | tee -a "$log"
  export OMPI_MCA_btl_vader_single_copy_mechanism=none
  if probe; then say "probe: ran with btl_vader_single_copy_mechanism=none (kept for the runs)"
  else say "probe failed again:"; tail -15 /tmp/mpi-probe.log | tee -a "$log"; exit 1; fi
fi

command -v taskset > /dev/null || say "no taskset: the runs use every core"
pin() {  # cpus command...
  if command -v taskset > /dev/null; then taskset -c "$@"; else shift; "$@"; fi
}
bench() {  # cpus threads [bench_mpi options]; a set that overruns 70 s keeps its lines so far
  say ""
  say "== cores $1, --threads $2 ${*:3} ($(date -u +%T))"
  pin "$1" timeout 70 python3 -u "$dev/bin/bench_mpi.py" --runs "$runs" --end 0.01 \
    --threads "$2" "${@:3}" 2>&1 | tee -a "$log"
  say "(rc ${PIPESTATUS[0]})"
}
bench 0,1 1
bench 0-3 1
bench 0,1 1 --set participants.granules.time_step_fraction=0.12
bench 0-3 2
say ""
say "done $(date -u +%T)"
