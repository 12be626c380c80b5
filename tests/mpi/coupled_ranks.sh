#!/usr/bin/env bash
# A coupled case with the DEM participant on several ranks beside one FE process, run by ctest
# (tests/CMakeLists.txt):
#   coupled_ranks.sh PARTITA SCENARIO
#
#   mpirun -n 1 partita run CASE --participant plate : -n N partita run CASE --participant granules
#
# The case: cases/uniaxial_compaction/steel.yaml (explicit-serial, the granules subcycling under
# the plate: displacements to the DEM's mesh, tractions back), shortened with --set.
# Scenarios:
#   identical   the granules on 1 (--on-ranks), 2 and 3 ranks: every CSV file (the monitors,
#               coupling.csv with the interface work) the same bytes; the granules on 2 ranks with
#               the controller leading them (granules first on the line): the same bytes again;
#               the plate's reaction at the end pushes it up (granules.plate.force_z and
#               plate.bottom.force_z > 0) and is of the order of the static load (10 kPa on
#               4 cm^2 plus the plate's weight: plate.static_reaction_z, 4.06 N): within a factor
#               of 3 of it; the split run's reaction within 1e-6 of the plain one-process DEM's
#               (the split sums in another order: the last bits differ, the physics does not);
#               the plate's lower face handed to the granules as their mesh (from:, one_sided:
#               true) with the vertices' forces back and the attached states read: the same bytes
#               on 1, 2 and 3 ranks, the reaction within the same bounds
#   resume      granules on 2 ranks to 0.6 ms with a restart file, resumed on 3 ranks to 1.2 ms,
#               against written on 3 and resumed on 1: the same CSV bytes (a split bed's restart
#               does not depend on the splits that write and read it; an uninterrupted run builds
#               its neighbour lists on other steps, so it differs in the last bits: subdomain.hpp)
#   stalled     the granules' rank 1 (rank 2 of the run) stopped (SIGSTOP) mid-run with
#               --peer-timeout 3: every process ends within 15 s, non-zero, the message naming the
#               participant's rank 1 and that it is rank 2 of the run; the same for the granules'
#               leader (rank 0, rank 1 of the run), named by the others
#   killed      the granules' rank 2 (rank 3 of the run) killed (SIGKILL) mid-run: every process
#               ends within 10 s, non-zero
#   implicit    rubber-implicit.yaml (implicit-serial, IQN-ILS: windows repeated from the DEM's
#               checkpoints, the split bed gathered and resumed on every rank) with the granules on
#               1 (--on-ranks), 2 and 3 ranks: every CSV file the same bytes; some window took more
#               than one iteration (a checkpoint was restored)
#   refused     the plate (a FE solver, which does not run on ranks) on 2 processes: refused
#               before any window, naming the participant and its solver, every process ended
#               within 60 s; a surface the plate does not have (from: plate.nothere) with the
#               granules on 3 ranks, refused by the controller in the handshake while the
#               granules' ranks follow their leader: every process ends within 30 s (not after
#               --peer-timeout), the controller's message first
# OpenMPI refuses to run as root unless told (CI runs as root); --oversubscribe: 4 processes on
# fewer cores. One OpenMP thread a process, passive waits.
set -uo pipefail
P=$(realpath "$1")
SCENARIO=$2
HERE=$(cd "$(dirname "$0")" && pwd)
CASE=$HERE/../../cases/uniaxial_compaction/steel.yaml
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 PARTITA_LOG_LEVEL=${PARTITA_LOG_LEVEL:-warn}
export OMPI_MCA_rmaps_base_oversubscribe=1 PARTITA_NO_PLOTS=1 OMP_NUM_THREADS=1 OMP_WAIT_POLICY=passive
MPIRUN=(mpirun --oversubscribe)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"
SHORT=(--set time.end=0.001 --set output.every=5e-4)
# the plate's lower face as the granules' mesh (instead of the STL), one-sided, with the
# vertices' forces back (scale.yaml's route) and the faces' attached states read
HANDED=(--set 'participants.granules.meshes=[{name: plate, from: plate.bottom, material: steel, one_sided: true}]'
        --set 'coupling.exchanges=[{data: displacement, from: plate.bottom, to: granules.plate, mapper: nearest-neighbor}, {data: force, from: granules.plate, to: plate.bottom, mapper: nearest-neighbor}, {data: attached, from: plate.bottom_centres, to: granules.plate_centres, mapper: nearest-neighbor}]')

fail() { echo "FAILED: $*" >&2; exit 1; }
. "$HERE/same_csv.sh"

# coupled N DIR [args...]: the plate in one process, the granules on N (1: --on-ranks), into DIR
coupled() {
  local n=$1 dir=$2 on=()
  shift 2
  [ "$n" -eq 1 ] && on=(--on-ranks)
  local start=$(date +%s%N)
  timeout 120 "${MPIRUN[@]}" -n 1 "$P" run "$CASE" -o "$dir" --threads 1 --participant plate "$@" : \
    -n "$n" "$P" run "$CASE" -o "$dir" --threads 1 --participant granules "${on[@]}" "$@" > "$dir.log" 2>&1 ||
    { local s=$?; cat "$dir.log" >&2; fail "the granules on $n rank(s) exited with $s"; }
  echo "granules on $n rank(s): $((($(date +%s%N) - start) / 1000000)) ms"
}

# same DIR_A DIR_B: every CSV file of A in B, byte for byte (and as many)
same() { same_csv "$1" "$2"; }

# find_rank R: the pid of this test's partita process of rank R of the run
find_rank() {
  local p
  for p in $(pgrep -x partita); do
    [ "$(readlink /proc/"$p"/cwd)" = "$WORK" ] &&
      tr '\0' '\n' < /proc/"$p"/environ 2> /dev/null | grep -qx "OMPI_COMM_WORLD_RANK=$1" && echo "$p"
  done
}

# under_way DIR: wait for the run's second VTK frame
under_way() {
  for _ in $(seq 1 600); do
    compgen -G "$1/vtk/*_000001.vt?" > /dev/null && return
    sleep 0.05
  done
}

case $SCENARIO in
identical)
  for n in 1 2 3; do coupled $n r$n "${SHORT[@]}"; done
  same r1 r2
  same r1 r3
  # the controller leading the granules' ranks (the granules first on the line)
  timeout 120 "${MPIRUN[@]}" -n 2 "$P" run "$CASE" -o c2 --threads 1 --participant granules "${SHORT[@]}" : \
    -n 1 "$P" run "$CASE" -o c2 --threads 1 --participant plate "${SHORT[@]}" > c2.log 2>&1 ||
    { cat c2.log >&2; fail "the controller leading the granules on 2 ranks"; }
  same r1 c2
  # the plain DEM in one process, for the physics
  timeout 120 "${MPIRUN[@]}" -n 1 "$P" run "$CASE" -o plain --threads 1 --participant plate "${SHORT[@]}" : \
    -n 1 "$P" run "$CASE" -o plain --threads 1 --participant granules "${SHORT[@]}" > plain.log 2>&1 ||
    { cat plain.log >&2; fail "the plain run"; }
  python3 - r3/reaction.csv plain/reaction.csv r3/coupling.csv << 'EOF' || fail "the reaction"
import csv, sys
def table(f):
    rows = list(csv.reader(open(f)))
    return {h.split(' [')[0]: k for k, h in enumerate(rows[0])}, [[float(v) for v in r] for r in rows[1:]]
col, split = table(sys.argv[1])
_, plain = table(sys.argv[2])
windows = len(list(csv.reader(open(sys.argv[3])))) - 1
assert windows == 100 and len(split) == windows + 1, (windows, len(split))
end = split[-1]
static = end[col['plate.static_reaction_z']]
assert abs(static - 4.0616) < 1e-3, static  # 10 kPa x 4 cm^2 + 7850 x 0.8 cm^3 x 9.81
for q in ('granules.plate.force_z', 'plate.bottom.force_z'):
    f = end[col[q]]
    assert 0.0 < f < 3.0 * static, (q, f, static)  # the granules hold the plate up
    p = plain[-1][col[q]]
    assert abs(f - p) <= 1e-6 * abs(p), (q, f, p)
print('reaction at the end: %.4g N (static %.4g N), the plain DEM\'s to %.1e' %
      (end[col['granules.plate.force_z']], static,
       abs(end[col['granules.plate.force_z']] / plain[-1][col['granules.plate.force_z']] - 1)))
EOF
  echo "the CSV files of the granules on 1, 2 and 3 ranks (and led by the controller) are the same bytes"
  # the plate's lower face handed to the granules as their contact mesh (from:, one-sided), the
  # vertices' forces back and the faces' attached states read: the same bytes on 1, 2 and 3 ranks
  for n in 1 2 3; do coupled $n h$n "${SHORT[@]}" "${HANDED[@]}"; done
  same h1 h2
  same h1 h3
  python3 - h3/reaction.csv << 'EOF' || fail "the reaction on the handed-over face"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
col = {h.split(' [')[0]: k for k, h in enumerate(rows[0])}
end = [float(v) for v in rows[-1]]
static = end[col['plate.static_reaction_z']]
for q in ('granules.plate.force_z', 'plate.bottom.force_z'):
    assert 0.0 < end[col[q]] < 3.0 * static, (q, end[col[q]], static)
print('the handed-over face: reaction %.4g N at the end' % end[col['granules.plate.force_z']])
EOF
  echo "the handed-over face: the same bytes on 1, 2 and 3 ranks"
  ;;
resume)
  # resume W R DIR: written with the granules on W ranks to 0.6 ms, resumed on R to 1.2 ms
  resume() {
    local w=$1 r=$2 dir=$3 on=()
    coupled "$w" "$dir" --set time.end=0.0006 --set output.every=2e-4 --set output.restart.at_end=true
    [ "$r" -eq 1 ] && on=(--on-ranks)
    local start=$(date +%s%N)
    timeout 120 "${MPIRUN[@]}" -n 1 "$P" run "$CASE" --resume "$dir" --threads 1 --participant plate --set time.end=0.0012 --set output.every=2e-4 : \
      -n "$r" "$P" run "$CASE" --resume "$dir" --threads 1 --participant granules "${on[@]}" --set time.end=0.0012 --set output.every=2e-4 > "$dir-2.log" 2>&1 ||
      { cat "$dir-2.log" >&2; fail "resumed with the granules on $r rank(s)"; }
    echo "resumed on $r rank(s): $((($(date +%s%N) - start) / 1000000)) ms"
    [ "$(tail -n 1 "$dir/reaction.csv" | cut -d, -f1)" = 0.0012 ] || fail "$dir: the resumed run did not reach 1.2 ms"
  }
  resume 2 3 a
  resume 3 1 b
  same a b
  echo "written on 2 ranks and resumed on 3, written on 3 and resumed on 1: the same bytes"
  ;;
stalled | killed)
  # stop RANK SIG LIMIT: rank RANK of the run sent SIG mid-run; every process ends within LIMIT s
  stop() {
    local victim_rank=$1 sig=$2 limit=$3
    rm -rf s
    timeout 120 "${MPIRUN[@]}" -n 1 "$P" run "$CASE" -o s --threads 1 --participant plate --peer-timeout 3 --set time.end=1 : \
      -n 3 "$P" run "$CASE" -o s --threads 1 --participant granules --peer-timeout 3 --set time.end=1 > s.log 2>&1 &
    local run=$!
    under_way s
    local victim=$(find_rank "$victim_rank")
    [ -n "$victim" ] || { kill $run; fail "no rank $victim_rank found"; }
    local start=$(date +%s)
    kill -"$sig" "$victim"
    wait $run
    local status=$?
    local took=$(($(date +%s) - start))
    kill -CONT "$victim" 2> /dev/null
    [ $status -ne 0 ] || fail "the run ended with status 0"
    [ $took -le "$limit" ] || fail "the run ended $took s after SIG$sig to rank $victim_rank"
    echo "rank $victim_rank of the run SIG$sig: every process ended after $took s, status $status: $(grep -m1 'partita: error' s.log | cut -c1-200)..."
  }
  # named (SIGSTOP): 1 is the participant's rank, "ranks 0, 1, 2 are ranks 1, 2, 3 of the run"
  named() {
    grep 'partita: error' s.log | grep -q "rank $1 is stuck or gone" || { cat s.log >&2; fail "rank $1 is not named"; }
    grep 'partita: error' s.log | grep -q "ranks 0, 1, 2 are ranks 1, 2, 3 of the run" ||
      { cat s.log >&2; fail "the message does not say which of the run's ranks that is"; }
  }
  if [ "$SCENARIO" = stalled ]; then
    stop 2 STOP 15  # the granules' rank 1: its leader names it
    named 1
    stop 1 STOP 15  # the granules' leader: the others name it
    named 0
  else
    stop 3 KILL 10  # the granules' rank 2
  fi
  ;;
implicit)
  # rubber-implicit.yaml (implicit-serial with IQN-ILS: each window repeated from checkpoints
  # until it converges) with the granules on 1 (--on-ranks), 2 and 3 ranks
  rubber=$HERE/../../cases/uniaxial_compaction/rubber-implicit.yaml
  for n in 1 2 3; do
    on=()
    [ "$n" -eq 1 ] && on=(--on-ranks)
    start=$(date +%s%N)
    timeout 120 "${MPIRUN[@]}" -n 1 "$P" run "$rubber" -o i$n --threads 1 --participant plate --set time.end=3e-4 --set output.every=1e-4 : \
      -n "$n" "$P" run "$rubber" -o i$n --threads 1 --participant granules "${on[@]}" --set time.end=3e-4 --set output.every=1e-4 > i$n.log 2>&1 ||
      { cat i$n.log >&2; fail "implicit with the granules on $n rank(s)"; }
    echo "implicit, granules on $n rank(s): $((($(date +%s%N) - start) / 1000000)) ms"
  done
  same i1 i2
  same i1 i3
  # the windows were repeated from the checkpoints: more than one iteration in some
  python3 - i3/coupling.csv << 'EOF' || fail "no window was repeated"
import csv, sys
rows = list(csv.DictReader(open(sys.argv[1])))
iterations = [int(r['iterations']) for r in rows]
assert len(rows) == 30 and max(iterations) > 1, iterations
print('implicit: %d windows, %d iterations (checkpoints restored %d times)' %
      (len(rows), sum(iterations), sum(iterations) - len(rows)))
EOF
  echo "implicit: the same bytes with the granules on 1, 2 and 3 ranks"
  ;;
refused)
  start=$(date +%s)
  timeout 60 "${MPIRUN[@]}" -n 2 "$P" run "$CASE" -o x --threads 1 --participant plate "${SHORT[@]}" : \
    -n 1 "$P" run "$CASE" -o x --threads 1 --participant granules "${SHORT[@]}" > x.log 2>&1
  status=$?
  [ $status -ne 0 ] && [ $status -ne 124 ] || { cat x.log >&2; fail "the plate on 2 processes: exit status $status"; }
  grep 'partita: error' x.log | grep -q "participant 'plate' runs on 2 processes.*solver 'fem' does not run on several ranks" ||
    { cat x.log >&2; fail "the plate on 2 processes: not refused naming it and its solver"; }
  ! grep -q "window 1/" x.log || fail "the plate on 2 processes: a window ran"
  echo "the plate on 2 processes: refused in $(($(date +%s) - start)) s: $(grep -m1 'partita: error' x.log | cut -c1-160)..."
  # a surface the plate does not have (from:) with the granules on 3 ranks: the controller refuses
  # it in the handshake, when the granules' ranks already follow their leader: every process ends
  # at once (not after --peer-timeout, 600 s by default). The controller says it before it tells
  # the others, but mpirun forwards each process's stderr on its own pipe, so the order of lines
  # from different processes is not guaranteed: the first error line names the cause whichever
  # process wrote it (the others quote the controller's reason), and the controller's own is there
  start=$(date +%s)
  bad=(--set 'participants.granules.meshes=[{name: plate, from: plate.nothere, material: steel}]'
       --set 'coupling.exchanges=[{data: displacement, from: plate.bottom, to: granules.plate, mapper: nearest-neighbor}, {data: force, from: granules.plate, to: plate.bottom, mapper: nearest-neighbor}]')
  timeout 60 "${MPIRUN[@]}" -n 1 "$P" run "$CASE" -o w --threads 1 --participant plate "${SHORT[@]}" "${bad[@]}" : \
    -n 3 "$P" run "$CASE" -o w --threads 1 --participant granules "${SHORT[@]}" "${bad[@]}" > w.log 2>&1
  status=$?
  took=$(($(date +%s) - start))
  [ $status -ne 0 ] && [ $status -ne 124 ] || { cat w.log >&2; fail "a surface the plate does not have: exit status $status"; }
  [ $took -le 30 ] || fail "a surface the plate does not have: every process ended after $took s"
  grep -m1 'partita: error' w.log | grep -q "participant 'plate' has no mesh 'nothere'; its meshes: bottom" ||
    { cat w.log >&2; fail "a surface the plate does not have: the first error does not name the missing mesh"; }
  grep 'partita: error' w.log | grep -q "^partita: error: participant 'plate' (rank 0): .*participant 'plate' has no mesh 'nothere'" ||
    { cat w.log >&2; fail "a surface the plate does not have: the controller's own message is missing"; }
  echo "a surface the plate does not have, the granules on 3 ranks: refused in $took s: $(grep -m1 'partita: error' w.log | cut -c1-160)..."
  ;;
*)
  fail "unknown scenario $SCENARIO"
  ;;
esac
