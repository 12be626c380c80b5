#!/usr/bin/env bash
# Runs on the lent 16-core device machine, in the repository root, on the bundle that
# bench/device/pack.sh made here (carry ['.dev']). One call, about 5 minutes:
#   1. the machine (processors, caches, the C library);
#   2. the threaded-solver and thread-count tests on all cores (the same bits on any count);
#   3. the DEM's thread scaling 1-16 of the large peer bed, twice (aim 12x at 16), the
#      second time with each step's time thread by thread (--profile);
#   4. the 263k-dof plate's factorisation and transient step at 1, 2, 4, 8 and 16 threads;
#   5. the 10^6-granule scale case on 2, 8 and 16 threads (time per participant, memory).
# Everything goes to $OUT/scaling.log (or ./scaling.log without $OUT).
set -uo pipefail
source "$(dirname "$0")/bundle.sh"
open_log scaling.log
step() { say ""; say "== $* ($(date -u +%T))"; }
run() { say "\$ $*"; "$@" 2>&1 | tee -a "$log"; say "(rc ${PIPESTATUS[0]})"; }
unpack_bundle || exit 1
export PARTITA_LOG_LEVEL=warn
# the tests find their files and the app through the paths compiled in
provide_build_paths | tee -a "$log"

step machine
run nproc
lscpu | grep -E '^(Model name|Socket|Core|Thread|NUMA node\(s\)|L1d|L2|L3)' | tee -a "$log"
say "vector sets: $(grep -m1 '^flags' /proc/cpuinfo | grep -oE '\b(avx2|fma|avx512f|avx512vl)\b' | tr '\n' ' ')"
ldd --version | head -1 | tee -a "$log"
run "$dev/bin/partita" --version

step "thread-count tests on $(nproc) processors"
run timeout 150 "$dev/bin/partita_tests" "[threads],[threaded-solve],[threaded-factorisation]"

step "DEM: large peer bed, thread scaling (twice; the second with where each step's time goes)"
run timeout 120 "$dev/bin/bench_dem_peers" --data "$dev/data" --case large --scaling --no-peer
run timeout 120 "$dev/bin/bench_dem_peers" --data "$dev/data" --case large --scaling --no-peer --profile

step "FEM: 170x170x2 plate (263k dofs), factorisation and steps by thread count"
for t in 1 2 4 8 16; do
  OMP_NUM_THREADS=$t run timeout 60 "$dev/bin/bench_fem_plate" 170x170x2 --no-static --no-ccx \
    --steps 6 --backends cholmod-nesdis-t,cholmod-nesdis-tf
done

step "scale case (10^6 granules, 10^5-element plate) on 2, 8 and 16 threads"
for t in 2 8; do
  say "\$ partita run cases/scale/scale.yaml --threads $t"
  "$dev/bin/partita" run cases/scale/scale.yaml --threads $t --output /tmp/scale-out 2>&1 |
    grep -E 'set-up of|summary' | tee -a "$log"
done
/usr/bin/time -v "$dev/bin/partita" run cases/scale/scale.yaml --threads 16 --output /tmp/scale-out \
  2>&1 | grep -v -E '^\s+(Average|Exit|Socket|Signals|Swaps|Page size|File system)' | tail -40 | tee -a "$log"
step done
