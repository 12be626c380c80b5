#!/usr/bin/env bash
# A DEM-only case on N ranks (mpirun -n N partita run CASE), run by ctest (tests/CMakeLists.txt):
#   dem_ranks.sh PARTITA SCENARIO
# Scenarios (the case: tests/mpi/dem_ranks_bed.yaml, a bed dropped in a box, pressed by a lid):
#   identical   the case on 1, 2, 3 and 4 ranks: every CSV file the same bytes on every N; the
#               monitors hold the contracts of the run (one row per window, the particle count
#               constant, the bed falling under gravity at the start, the lid pressing it onto
#               the floor and against the box's sides at the end; the energy books close); each
#               VTK frame's .pvtp joins
#               one piece per rank whose particles add up to the bed, every piece holding some,
#               the fullest at the end at most 1.5 times the mean (the bed cut again as the load
#               drifts), and declares the pieces' arrays as they hold them; the particles file
#               (output.particles_file) the same bytes on every N, read back as the bed at the end;
#               a run on 2 ranks into the 4-rank run's folder leaves none of its pieces
#   resume      written on 2 ranks to 10 ms (restart file), resumed on 3 to 20 ms, against written
#               on 4 and resumed on 1: the same bytes (a split bed's restart does not depend on the
#               splits that write and read it); resumed without mpirun it is refused, saying why
#   lost        a particle leaves the domain: the run stops with exit status 1 and one message
#               naming it, the same on 1 and 3 ranks
#   stalled     rank 1 stopped (SIGSTOP) mid-run with --peer-timeout 3: every process ends within
#               15 s, non-zero, the message naming rank 1
#   servo       the lid as a servo wall to 1 N: the same bytes on 1 and 3 ranks, the lid's force
#               within 2 % of its target at the end
#   signal      SIGINT to mpirun mid-run on 2 ranks: every process ends within 10 s after the
#               window, with a restart file, which resumes on 3 ranks to the end
#   signal-rank SIGINT to rank 1's process alone: the same stop (status 130, a restart file)
#   crushing    the case with breakage (granules weaker than the lid's load, fragments below the
#               comminution limit crushed to powder) on 1, 2, 3 and 4 ranks: every CSV file (the
#               grading too) and the particles file the same bytes; dozens broken, the particle
#               count that of the fragments and the powder, the mass kept or counted as powder,
#               the books closed with the breakage booked; and a restart written on 2 ranks
#               mid-crushing, resumed on 3, the bytes of one written on 4 and resumed on 1
#   refused     on 2 ranks, a case of two participants: exit status 1, one message naming them
#               and --participant, every process ended within 60 s
# OpenMPI refuses to run as root unless told (CI runs as root); --oversubscribe: 4 ranks on fewer
# cores. One OpenMP thread a rank.
set -uo pipefail
P=$(realpath "$1")
SCENARIO=$2
HERE=$(cd "$(dirname "$0")" && pwd)
CASE=$HERE/dem_ranks_bed.yaml
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 PARTITA_LOG_LEVEL=${PARTITA_LOG_LEVEL:-warn}
export OMPI_MCA_rmaps_base_oversubscribe=1 PARTITA_NO_PLOTS=1 OMP_NUM_THREADS=1
MPIRUN=(mpirun --oversubscribe)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"

fail() { echo "FAILED: $*" >&2; exit 1; }
. "$HERE/same_csv.sh"

# ranks N DIR [args...]: the case on N ranks into DIR
ranks() {
  local n=$1 dir=$2
  shift 2
  "${MPIRUN[@]}" -n "$n" "$P" run "$CASE" -o "$dir" --threads 1 "$@" > "$dir.log" 2>&1 ||
    { local s=$?; cat "$dir.log" >&2; fail "the case on $n rank(s) exited with $s"; }
}

# rank1_of_run DIR: after the run into DIR (started in the background) wrote its first frame,
# the process id of its rank 1 (this test's: started in its folder)
rank1_of_run() {
  for _ in $(seq 1 600); do
    compgen -G "$1/vtk/*_000001.pvtp" > /dev/null && break
    sleep 0.05
  done
  for p in $(pgrep -x partita); do
    [ "$(readlink /proc/"$p"/cwd)" = "$WORK" ] &&
      tr '\0' '\n' < /proc/"$p"/environ 2> /dev/null | grep -qx "OMPI_COMM_WORLD_RANK=1" && echo "$p"
  done
}

# same DIR_A DIR_B: every CSV file of A in B, byte for byte (and as many), and the particles file
same() {
  cmp "$1/bed.data" "$2/bed.data" || fail "bed.data (the particles file): $1 and $2 differ"
  same_csv "$1" "$2"
}

case $SCENARIO in
identical)
  for n in 1 2 3 4; do
    start=$(date +%s%N)
    ranks $n r$n
    echo "$n rank(s): $((($(date +%s%N) - start) / 1000000)) ms"
  done
  for n in 2 3 4; do same r1 r$n; done
  # the same case in one process without mpirun (one System, its own energy accounting)
  "$P" run "$CASE" -o r0 --threads 1 > r0.log 2>&1 || { cat r0.log >&2; fail "the case without mpirun"; }
  python3 - r1/bed.csv r1/coupling.csv r0/bed.csv << 'EOF' || fail "the monitors of the run"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
head, data = rows[0], [[float(v) for v in r] for r in rows[1:]]
col = {h.split(' [')[0]: k for k, h in enumerate(head)}
windows = len(list(csv.reader(open(sys.argv[2])))) - 1
assert len(data) == windows + 1, (len(data), windows)   # t = 0 and every window
n = {r[col['bed.particles']] for r in data}
assert len(n) == 1 and 100 < n.pop() < 1000, 'the particle count changes or is not a few hundred'
assert len({r[col['bed.mass']] for r in data}) == 1, 'the mass changes'
# released at rest: the bed falls under gravity (p_z < 0, growing) before it meets the floor
t1 = next(r for r in data if r[0] >= 1e-3)
assert data[0][col['bed.momentum_z']] == 0.0 and t1[col['bed.momentum_z']] < 0.0, t1
# at the end the lid (coming down from 10 ms) and the floor hold the bed between them
end = data[-1]
assert end[col['bed.lid.force_z']] > 0.0 and end[col['bed.floor.force_z']] < 0.0, end
assert end[col['bed.elastic_energy']] > 0.0, end
# a packed bed has a few contacts per particle (at most 12 for equal spheres), none before it lands
assert 1.0 < end[col['bed.contacts_per_particle']] < 12.0, end
assert t1[col['bed.contacts_per_particle']] < 1.0, t1
# and pushes the box's side faces outwards
assert end[col['bed.box.xmin.force_x']] < 0.0 and end[col['bed.box.ymax.force_y']] > 0.0, end
# the energy books: gravity and the lid work on the bed, friction and damping dissipate, the
# resting floor does no work, and the books close at the end (the trapezoidal rule's error on the
# springs; the relative error peaks at 1.6e-2 as the lid lands, when the works are still small)
assert end[col['bed.gravity_work']] > 0.0 and end[col['bed.lid.work']] > 0.0, end
assert end[col['bed.friction_work']] > 0.0 and end[col['bed.damping_work']] > 0.0, end
assert end[col['bed.floor.work']] == 0.0, end
assert abs(end[col['bed.energy_balance_error']]) < 2e-3, end
# and they are one process's books of the same run (its sums in another order: the digits, not
# the bits)
one = list(csv.reader(open(sys.argv[3])))
one_col = {h.split(' [')[0]: k for k, h in enumerate(one[0])}
one_end = [float(v) for v in one[-1]]
books = ['bed.gravity_work', 'bed.friction_work', 'bed.damping_work', 'bed.lid.work']
scale = sum(abs(end[col[q]]) for q in books)
for q in books + ['bed.kinetic_energy', 'bed.elastic_energy']:
    assert abs(end[col[q]] - one_end[one_col[q]]) <= 1e-6 * scale, (q, end[col[q]], one_end[one_col[q]])
print('monitors:', len(data), 'rows, the contracts hold; the energy books close to %.2g at the end'
      ' and match one process\'s' % end[col['bed.energy_balance_error']])
EOF
  # the particles file reads back (particles: {file: ...}) as the bed it was written from: at the
  # start of a run from it, the count, the mass and particle 7's height are those at the end
  ranks 2 back --set "participants.bed.particles={material: grain, file: $WORK/r1/bed.data}" \
    --set time.end=2e-4 --set participants.bed.output.particles_file=none
  python3 - r1/bed.csv back/bed.csv << 'EOF' || fail "the particles file does not read back"
import csv, sys
end, start = list(csv.reader(open(sys.argv[1]))), list(csv.reader(open(sys.argv[2])))
col = {h.split(' [')[0]: k for k, h in enumerate(end[0])}
for q in ('bed.particles', 'bed.mass', 'bed.particle.7.z'):
    assert end[-1][col[q]] == start[1][col[q]], (q, end[-1][col[q]], start[1][col[q]])
print('the particles file reads back: count, mass and particle 7 as at the end')
EOF
  # each frame's .pvtp joins one piece per rank, whose particles add up to the bed
  total=$(python3 -c "import csv; r=list(csv.reader(open('r1/bed.csv'))); h=[x.split(' [')[0] for x in r[0]].index('bed.particles'); print(int(float(r[1][h])))")
  for n in 1 2 3 4; do
    frames=(r$n/vtk/bed_particles_*.pvtp)
    [ ${#frames[@]} -ge 4 ] || fail "$n rank(s): ${#frames[@]} .pvtp frames"
    grep -q "bed_particles_000000.pvtp" r$n/vtk/bed_particles.pvd || fail "$n rank(s): the series names no .pvtp"
    for f in "${frames[@]}"; do
      [ "$(grep -c '<Piece Source=' "$f")" -eq $n ] || fail "$f: not $n pieces"
      sum=0
      most=0
      for piece in $(sed -n 's/.*<Piece Source="\([^"]*\)".*/\1/p' "$f"); do
        c=$(grep -ao '<Piece NumberOfPoints="[0-9]*"' "r$n/vtk/$piece" | grep -o '[0-9]*')
        [ -n "$c" ] || fail "r$n/vtk/$piece: no piece"
        [ "$c" -gt 0 ] || fail "r$n/vtk/$piece: no particle on this rank"
        sum=$((sum + c))
        [ "$c" -gt "$most" ] && most=$c
      done
      [ "$sum" -eq "$total" ] || fail "$f: $sum particles in its pieces, the bed has $total"
    done
    # the settled, pressed bed is cut again as the load drifts: the last frame's fullest rank
    # holds at most 1.5 times the mean
    [ $((2 * n * most)) -le $((3 * total)) ] || fail "r$n: $most particles on one rank at the end"
  done
  # what a reader of the .pvtp expects of each piece: the point arrays it declares (name, type,
  # components) are the piece's, in order, and so is the points' type
  python3 - r4/vtk/bed_particles_000002.pvtp << 'EOF' || fail "a .pvtp does not describe its pieces"
import os, re, sys
pv = open(sys.argv[1]).read()
arrays = lambda text, tag: re.findall(r'<%s type="(\w+)"(?: Name="(\w+)")? NumberOfComponents="(\d)"' % tag, text)
point_data = arrays(pv.split('<PPoints>')[0], 'PDataArray')
points = arrays(pv.split('<PPoints>')[1], 'PDataArray')
pieces = re.findall(r'<Piece Source="([^"]+)"/>', pv)
assert len(pieces) == 4 and len(point_data) == 5 and len(points) == 1, (pieces, point_data)
for piece in pieces:
    head = open(os.path.join(os.path.dirname(sys.argv[1]), piece), 'rb').read()
    head = head.split(b'<AppendedData')[0].decode()
    assert arrays(head.split('<PointData>')[1].split('</PointData>')[0], 'DataArray') == point_data, piece
    assert arrays(head.split('<Points>')[1].split('</Points>')[0], 'DataArray') == points, piece
print("the .pvtp declares its pieces' arrays")
EOF
  # a new run into a folder of a run on more ranks leaves none of the earlier pieces
  ranks 2 r4
  stale=$(ls r4/vtk | grep -c '^bed_particles_[0-9]*_[23]\.vtp$')
  [ "$stale" -eq 0 ] || fail "$stale pieces of the 4-rank run left beside the 2-rank run's"
  echo "the CSV files of 1, 2, 3 and 4 ranks are the same bytes; the frames join $total particles"
  ;;
resume)
  ranks 2 a --set time.end=0.01 --set output.restart.at_end=true
  # (a restart file written on ranks does not resume without mpirun: refused, saying so; the
  # bouncing sphere, whose monitors one process reports too)
  sphere=$HERE/../../cases/bouncing_sphere/bouncing_sphere.yaml
  "${MPIRUN[@]}" -n 2 "$P" run "$sphere" -o crossed --threads 1 --set time.end=0.004 \
    --set output.restart.at_end=true > crossed.log 2>&1 || { cat crossed.log >&2; fail "the sphere on 2 ranks"; }
  "$P" run "$sphere" --resume crossed --threads 1 --set time.end=0.008 > crossed.log 2>&1 &&
    fail "a restart file of ranks resumed without mpirun"
  grep -q "written on ranks, mpirun -n N partita run, resumes on ranks" crossed.log ||
    { cat crossed.log >&2; fail "the refusal does not say why"; }
  "${MPIRUN[@]}" -n 3 "$P" run "$CASE" --resume a --threads 1 --set time.end=0.02 > a2.log 2>&1 ||
    { cat a2.log >&2; fail "resumed on 3 ranks"; }
  ranks 4 b --set time.end=0.01 --set output.restart.at_end=true
  "${MPIRUN[@]}" -n 1 "$P" run "$CASE" --resume b --threads 1 --set time.end=0.02 > b2.log 2>&1 ||
    { cat b2.log >&2; fail "resumed on 1 rank"; }
  same a b
  [ "$(tail -n 1 a/bed.csv | cut -d, -f1)" = 0.02 ] || fail "the resumed run did not reach 20 ms: $(tail -n 1 a/bed.csv)"
  echo "written on 2 and resumed on 3, written on 4 and resumed on 1: the same bytes"
  ;;
crushing)
  crush=(--set 'participants.bed.breakage={limit_strength: 0.3 MPa, reference_size: 2 mm, weibull_modulus: 10, comminution_limit: 1.2 mm, below_limit: powder, pattern: equal-4, mass: restored}'
         --set 'monitors[0].quantities=[bed.particles, bed.mass, bed.breakage.events, bed.breakage.fragments, bed.breakage.powder_events, bed.breakage.powder_mass, bed.breakage_energy, bed.energy_balance_error]'
         --set participants.bed.time_step_fraction=0.1)  # (the default for e = 0.5: the books close to 3e-3; at the case's 0.2, 5e-3)
  for n in 1 2 3 4; do
    start=$(date +%s%N)
    ranks $n k$n "${crush[@]}"
    echo "$n rank(s): $((($(date +%s%N) - start) / 1000000)) ms"
  done
  for n in 2 3 4; do same k1 k$n; done
  python3 - k1/bed.csv << 'EOF' || fail "the crushing run's monitors"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
col = {h.split(' [')[0]: k for k, h in enumerate(rows[0])}
data = [[float(v) for v in r] for r in rows[1:]]
first, end = data[0], data[-1]
q = lambda r, name: r[col['bed.' + name]]
events, powder = q(end, 'breakage.events'), q(end, 'breakage.powder_events')
assert events >= 20 and powder >= 5, (events, powder)
assert q(end, 'breakage.fragments') == 4 * events, end
# every broken granule gave 4 fragments, every powdered one left
assert q(end, 'particles') == q(first, 'particles') + 3 * events - powder, end
# the fragments carry their parent's mass (restored), the powder's is counted
assert abs(q(end, 'mass') + q(end, 'breakage.powder_mass') - q(first, 'mass')) < 1e-9 * q(first, 'mass'), end  # (10 digits in the CSV)
assert q(end, 'breakage_energy') > 0.0, end
assert abs(q(end, 'energy_balance_error')) < 5e-3, end
print(f"broken {events:.0f}, to powder {powder:.0f}, particles {q(first, 'particles'):.0f} -> "
      f"{q(end, 'particles'):.0f}, balance {q(end, 'energy_balance_error'):.2e}")
EOF
  ranks 2 ka "${crush[@]}" --set time.end=0.014 --set output.restart.at_end=true
  "${MPIRUN[@]}" -n 3 "$P" run "$CASE" --resume ka --threads 1 "${crush[@]}" --set time.end=0.02 > ka2.log 2>&1 ||
    { cat ka2.log >&2; fail "the crushing run resumed on 3 ranks"; }
  ranks 4 kb "${crush[@]}" --set time.end=0.014 --set output.restart.at_end=true
  "${MPIRUN[@]}" -n 1 "$P" run "$CASE" --resume kb --threads 1 "${crush[@]}" --set time.end=0.02 > kb2.log 2>&1 ||
    { cat kb2.log >&2; fail "the crushing run resumed on 1 rank"; }
  same ka kb
  [ "$(tail -n 1 ka/bed.csv | cut -d, -f1)" = 0.02 ] || fail "the resumed run did not reach 20 ms"
  echo "crushing: written on 2 and resumed on 3, written on 4 and resumed on 1: the same bytes"
  ;;
refused)
  # a case of two participants on 2 ranks: refused, naming them and --participant
  timeout 60 "${MPIRUN[@]}" -n 2 "$P" run "$HERE/../../cases/uniaxial_compaction/steel.yaml" -o y \
    --threads 1 > y.log 2>&1
  status=$?
  [ $status -ne 0 ] && [ $status -ne 124 ] || { cat y.log >&2; fail "two participants: exit status $status"; }
  grep 'partita: error' y.log | grep -q "2 participants (plate, granules).*--participant" ||
    { cat y.log >&2; fail "two participants: not refused naming them"; }
  echo "two participants: $(grep 'partita: error' y.log | cut -c1-150)..."
  ;;
lost)
  # gravity upwards, the lid replaced by a floor far below, lost_margin 1 mm: the rising bed leaves
  # the domain; the run stops with the state check's message, the same on 1 and 3 ranks
  lost=(--set 'participants.bed.gravity=[0, 0, 500]' --set 'participants.bed.walls[1].plane.point=[0, 0, -1]'
        --set 'participants.bed.walls[1].plane.normal=[0, 0, 1]' --set 'participants.bed.walls[1].velocity=[0, 0, 0]'
        --set 'participants.bed.lost_margin=1 mm')
  for n in 1 3; do
    start=$(date +%s)
    timeout 60 "${MPIRUN[@]}" -n $n "$P" run "$CASE" -o l$n --threads 1 "${lost[@]}" > l$n.log 2>&1
    status=$?
    [ $status -eq 1 ] || { cat l$n.log >&2; fail "a lost particle on $n rank(s): exit status $status"; }
    [ "$(grep -c 'partita: error' l$n.log)" -eq 1 ] || { cat l$n.log >&2; fail "$n rank(s): not one message"; }
    grep 'partita: error' l$n.log | grep -q 'particle [0-9]* is lost' || { cat l$n.log >&2; fail "$n rank(s): no lost particle named"; }
    echo "$n rank(s): stopped in $(($(date +%s) - start)) s: $(grep 'partita: error' l$n.log | cut -c1-110)..."
  done
  [ "$(grep 'partita: error' l1.log)" = "$(grep 'partita: error' l3.log)" ] || fail "the messages on 1 and 3 ranks differ"
  ;;
stalled)
  # rank 1 stopped (SIGSTOP) mid-run with --peer-timeout 3: every process ends within 15 s, the
  # message naming rank 1
  timeout 120 "${MPIRUN[@]}" -n 2 "$P" run "$CASE" -o s --threads 1 --peer-timeout 3 --set time.end=1 > s.log 2>&1 &
  run=$!
  victim=$(rank1_of_run s | head -n 1)
  [ -n "$victim" ] || { kill $run; fail "no rank 1 found"; }
  start=$(date +%s)
  kill -STOP "$victim"
  wait $run
  status=$?
  took=$(($(date +%s) - start))
  kill -CONT "$victim" 2> /dev/null
  [ $status -ne 0 ] || fail "the run ended with status 0"
  [ $took -le 15 ] || fail "the run ended $took s after rank 1 stopped"
  grep -q 'partita: error' s.log || { cat s.log >&2; fail "no message"; }
  grep -q "rank 1 is stuck or gone" s.log || { cat s.log >&2; fail "rank 1 is not named"; }
  echo "rank 1 stopped: every process ended after $took s, status $status: $(grep -m1 'partita: error' s.log | cut -c1-150)..."
  ;;
signal)
  # SIGINT to mpirun mid-run (it passes SIGTERM on): rank 0 finishes the window, writes the
  # restart file with the others and every process ends within 10 s; the restart resumes on 3
  # ranks to the end
  still=(--set 'participants.bed.walls[1].velocity=[0, 0, 0]')  # (a lid at rest: a long run)
  "${MPIRUN[@]}" -n 2 "$P" run "$CASE" -o g --threads 1 --set time.end=1 "${still[@]}" > g.log 2>&1 &
  run=$!
  for _ in $(seq 1 600); do
    compgen -G "g/vtk/*_000001.pvtp" > /dev/null && break
    sleep 0.05
  done
  start=$(date +%s)
  kill -INT $run
  wait $run
  took=$(($(date +%s) - start))
  [ $took -le 10 ] || fail "the run ended $took s after SIGINT"
  grep -q "stopped by signal" g.log || { cat g.log >&2; fail "no stop by signal"; }
  compgen -G "g/restart/w*.bin" > /dev/null || { cat g.log >&2; fail "no restart file"; }
  # where the signal stopped it depends on the machine's speed: resume to 0.02 s beyond that
  stopped=$(grep -o 'after window [0-9]* (t = [0-9.e+-]* s)' g.log | head -n 1 | sed 's/.*t = \(.*\) s)/\1/')
  [ -n "$stopped" ] || { cat g.log >&2; fail "no stop time in the log"; }
  end=$(python3 -c "print(round($stopped + 0.02, 9))")
  "${MPIRUN[@]}" -n 3 "$P" run "$CASE" --resume g --threads 1 --set time.end=$end "${still[@]}" > g2.log 2>&1 ||
    { cat g2.log >&2; fail "resumed on 3 ranks"; }
  python3 -c "import sys; t = float(open('g/bed.csv').read().split()[-1].split(',')[0]); sys.exit(abs(t - $end) > 1e-9)" ||
    fail "the resumed run did not reach $end s"
  echo "SIGINT: every process ended after $took s with a restart file ($(ls g/restart)) at $stopped s, resumed on 3 ranks to $end s"
  ;;
signal-rank)
  # SIGINT to rank 1's process alone (a batch system's signal to one process, or kill): rank 1
  # passes it on to rank 0 with the window's check, and the run stops after the window as for a
  # signal to mpirun: every process ends within 10 s, status 130, with a restart file
  still=(--set 'participants.bed.walls[1].velocity=[0, 0, 0]')
  "${MPIRUN[@]}" -n 2 "$P" run "$CASE" -o h --threads 1 --set time.end=1 "${still[@]}" > h.log 2>&1 &
  run=$!
  victim=$(rank1_of_run h | head -n 1)
  [ -n "$victim" ] || { kill $run; fail "no rank 1 found"; }
  start=$(date +%s)
  kill -INT "$victim"
  wait $run
  status=$?
  took=$(($(date +%s) - start))
  [ $took -le 10 ] || { kill -TERM $run 2> /dev/null; fail "the run ended $took s after SIGINT to rank 1"; }
  [ "$status" -eq 130 ] || { cat h.log >&2; fail "exit status $status after SIGINT to rank 1 (expected 130)"; }
  grep -q "stopped by signal 2" h.log || { cat h.log >&2; fail "no stop by signal"; }
  compgen -G "h/restart/w*.bin" > /dev/null || { cat h.log >&2; fail "no restart file"; }
  echo "SIGINT to rank 1 alone: every process ended after $took s, status $status, with a restart file ($(ls h/restart))"
  ;;
servo)
  # the lid as a servo wall to 1 N (the law applied with the force summed over the ranks): the
  # same bytes on 1 and 3 ranks, and the lid holds the bed at its target at the end
  servo=(--set 'participants.bed.walls[1]={name: lid, plane: {point: [0, 0, 18 mm], normal: [0, 0, -1]}, material: grain, servo: {force: 1 N, max_velocity: 0.5}}')
  ranks 1 v1 "${servo[@]}"
  ranks 3 v3 "${servo[@]}"
  same v1 v3
  python3 - v3/bed.csv << 'EOF' || fail "the servo lid does not hold its target"
import csv, sys
rows = list(csv.reader(open(sys.argv[1])))
k = [h.split(' [')[0] for h in rows[0]].index('bed.lid.force_z')
f = float(rows[-1][k])
assert abs(f - 1.0) < 0.02, f   # the particles push the lid back with the target force
print('the servo lid holds', f, 'N of 1 N at the end')
EOF
  ;;
*)
  fail "unknown scenario $SCENARIO"
  ;;
esac
