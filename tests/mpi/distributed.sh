#!/usr/bin/env bash
# Participants as processes over MPI, run by ctest (tests/CMakeLists.txt):
#   distributed.sh PARTITA SCENARIO [ARGS...]
# Scenarios:
#   identical CASE A B [--set ...]   the case in one process, then A and B in two processes: every
#                                    CSV file and every VTK file byte for byte the same
#   resume CASE A B END1 END2        two processes to END1 with restart files, resumed to END2, against
#                                    one process to END2: the same bytes (CSV, VTK, last restart file)
#   failure                          tests/mpi/tube_explicit.yaml, whose fluid fails in window 3 (0-based),
#                                    with the fluid in the second process: both processes end within
#                                    10 s, non-zero, naming the participant and its error
#   changed-case                     the second process reads another time.end: refused at start-up,
#                                    naming the mismatch, before any window
#   sigkill                          the second process killed (SIGKILL) mid-run: mpirun ends within 10 s
#   external-read PLUGIN PROBE SEES an external program (read_probe.cpp) reads the plugin solver
#                                    ramp's field, linear in time, at 0, dt/3, dt/2 and dt of each
#                                    step with reader_sees SEES: the analytic value (within 1e-12),
#                                    times outside the step refused
#   external-no-restart PLUGIN PROBE the same program (which gives no restart writer) in a case with
#                                    output.restart: refused before the first window, naming the
#                                    program and set_restart_writer() before initialize()
#   signal                           SIGINT to the second process: every process ends after the window
#                                    with status 130 and a restart file; resumed, the run gives the
#                                    bytes of an uninterrupted one
# OpenMPI refuses to run as root unless told: CI runs as root (ctest sets both variables on these
# tests; they are harmless for other users). --oversubscribe: two processes may share fewer cores.
set -uo pipefail
P=$1
SCENARIO=$2
shift 2
HERE=$(cd "$(dirname "$0")" && pwd)
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1 PARTITA_LOG_LEVEL=${PARTITA_LOG_LEVEL:-warn}
export OMPI_MCA_rmaps_base_oversubscribe=1
MPIRUN=(mpirun --oversubscribe)
WORK=$(mktemp -d)
trap 'rm -rf "$WORK"' EXIT
cd "$WORK"

fail() { echo "FAILED: $*" >&2; exit 1; }

# wait until the run in two/ is under way: its second VTK frame (the CSV files are flushed only
# every 2 s; frames are written as they come)
under_way() {
  for _ in $(seq 1 600); do
    compgen -G "two/vtk/*_000001.vt?" > /dev/null && return
    sleep 0.05
  done
}

# the pid of the partita process (not mpirun's, whose command line names it too) of participant $1
participant_pid() {
  local p
  for p in $(pgrep -f -- "--participant $1"); do
    [ "$(cat /proc/"$p"/comm 2> /dev/null)" = partita ] && { echo "$p"; return; }
  done
}

# two processes: distributed A B DIR [args...]
distributed() {
  local a=$1 b=$2 dir=$3 case_file=$4
  shift 4
  "${MPIRUN[@]}" -n 1 "$P" run "$case_file" -o "$dir" --threads 1 --participant "$a" "$@" : \
                 -n 1 "$P" run "$case_file" -o "$dir" --threads 1 --participant "$b" "$@"
}

same_files() {  # dir1 dir2
  local n=0 f
  for f in "$1"/*.csv; do
    cmp "$f" "$2/$(basename "$f")" || fail "$(basename "$f") differs between $1 and $2"
    n=$((n + 1))
  done
  [ "$n" -gt 0 ] || fail "no CSV files in $1"
  (cd "$1/vtk" && md5sum -- * | sort) > "$WORK/a.md5"
  (cd "$2/vtk" && md5sum -- * | sort) > "$WORK/b.md5"
  diff "$WORK/a.md5" "$WORK/b.md5" > /dev/null || fail "VTK files differ between $1 and $2"
  echo "same bytes: $n CSV files and $(wc -l < "$WORK/a.md5") VTK files"
}

case "$SCENARIO" in
  identical)
    case_file=$1 a=$2 b=$3
    shift 3
    "$P" run "$case_file" -o one --threads 1 "$@" > one.log 2>&1 || { cat one.log; fail "the run in one process failed"; }
    distributed "$a" "$b" two "$case_file" "$@" > two.log 2>&1 || { cat two.log; fail "the run in two processes failed"; }
    same_files one two
    ;;
  resume)
    case_file=$1 a=$2 b=$3 end1=$4 end2=$5
    # output.every divides END1: the last frame of the first part is a frame of the whole run
    r="--set output.restart.every_windows=10 --set output.every=2e-4"
    "$P" run "$case_file" -o one --threads 1 --set time.end="$end2" $r > one.log 2>&1 || { cat one.log; fail "one process"; }
    distributed "$a" "$b" two "$case_file" --set time.end="$end1" $r > two.log 2>&1 || { cat two.log; fail "two processes to $end1"; }
    "${MPIRUN[@]}" -n 1 "$P" run "$case_file" --resume two --threads 1 --participant "$a" --set time.end="$end2" $r : \
                   -n 1 "$P" run "$case_file" --resume two --threads 1 --participant "$b" --set time.end="$end2" $r \
                   > resume.log 2>&1 || { cat resume.log; fail "the resumed run in two processes"; }
    same_files one two
    last=$(ls one/restart | tail -1)
    cmp "one/restart/$last" "two/restart/$last" || fail "restart file $last differs"
    echo "same restart file $last"
    ;;
  failure)
    start=$(date +%s.%N)
    distributed solid fluid two "$HERE/tube_explicit.yaml" > two.log 2>&1
    status=$?
    took=$(echo "$(date +%s.%N) - $start" | bc)
    cat two.log
    [ "$status" -ne 0 ] || fail "exit status 0 after a participant failed"
    grep -q "participant 'fluid' (rank 1) failed: tube1d-fluid: tube1d flow: Newton did not converge" two.log ||
      fail "no message naming the failed participant and its error"
    grep -q "at t = 0.04" two.log || fail "the failure is not the one of window 3 (t = 0.04 s)"
    [ "$(echo "$took < 10" | bc)" = 1 ] || fail "the run took $took s to end (limit 10 s)"
    echo "ended in $took s with status $status"
    ;;
  changed-case)
    case_file=$HERE/tube_explicit.yaml
    "${MPIRUN[@]}" -n 1 "$P" run "$case_file" -o two --threads 1 --participant fluid : \
                   -n 1 "$P" run "$case_file" -o two --threads 1 --participant solid --set time.end=0.5 \
                   > two.log 2>&1
    status=$?
    cat two.log
    [ "$status" -ne 0 ] || fail "exit status 0 with two different cases"
    grep -q "its case differs from this process's" two.log || fail "no message naming the mismatch"
    [ ! -s two/coupling.csv ] || fail "a window ran before the mismatch was found"
    ;;
  sigkill)
    case_file=$HERE/../../cases/uniaxial_compaction/steel.yaml
    distributed plate granules two "$case_file" --set time.end=1.0 > two.log 2>&1 &
    launcher=$!
    under_way
    pid=$(participant_pid granules)
    [ -n "$pid" ] || fail "no process runs participant granules"
    kill -9 "$pid"
    killed=$(date +%s.%N)
    for _ in $(seq 1 150); do kill -0 "$launcher" 2> /dev/null || break; sleep 0.1; done
    took=$(echo "$(date +%s.%N) - $killed" | bc)
    if kill -0 "$launcher" 2> /dev/null; then
      pkill -9 -f -- "--participant plate"
      fail "mpirun still runs 15 s after one process was killed"
    fi
    wait "$launcher"
    status=$?
    [ "$status" -ne 0 ] || fail "exit status 0 after a process was killed"
    [ "$(echo "$took < 10" | bc)" = 1 ] || fail "the run took $took s to end after SIGKILL (limit 10 s)"
    echo "ended $took s after SIGKILL, status $status"
    ;;
  signal)
    case_file=$HERE/../../cases/uniaxial_compaction/steel.yaml
    sets=(--set time.end=0.02 --set output.every=2e-3)  # long enough to be under way at the signal
    "$P" run "$case_file" -o one --threads 1 "${sets[@]}" > one.log 2>&1 || { cat one.log; fail "one process"; }
    distributed plate granules two "$case_file" "${sets[@]}" > two.log 2>&1 &
    launcher=$!
    under_way
    pid=$(participant_pid granules)
    [ -n "$pid" ] || fail "no process runs participant granules"
    kill -INT "$pid"
    wait "$launcher"
    status=$?
    cat two.log
    [ "$status" -eq 130 ] || fail "exit status $status after SIGINT (expected 130)"
    [ "$(grep -c '^partita run: .* stopped by signal 2' two.log)" -eq 2 ] || fail "not every process stopped by the signal"
    ls two/restart/*.bin > /dev/null 2>&1 || fail "no restart file"
    "${MPIRUN[@]}" -n 1 "$P" run "$case_file" --resume two --threads 1 --participant plate "${sets[@]}" : \
                   -n 1 "$P" run "$case_file" --resume two --threads 1 --participant granules "${sets[@]}" \
                   > resume.log 2>&1 || { cat resume.log; fail "the resumed run"; }
    same_files one two
    ;;
  external-read)
    plugin=$1 probe=$2 sees=$3
    set_sees=(--set "coupling.exchanges[0].reader_sees=$sees")
    "${MPIRUN[@]}" -n 1 "$P" run "$HERE/external_read.yaml" -o two --threads 1 --plugin "$plugin" \
                   --participant ramp "${set_sees[@]}" : \
                   -n 1 "$probe" "$HERE/external_read.yaml" "$sees" "${set_sees[@]}" > two.log 2>&1
    status=$?
    cat two.log
    [ "$status" -eq 0 ] || fail "the run with the external program failed (status $status)"
    grep -q "^read_probe: passed" two.log || fail "the program's reads are not the analytic values"
    ;;
  external-no-restart)
    plugin=$1 probe=$2
    restart=(--set output.restart.every_windows=2)
    "${MPIRUN[@]}" -n 1 "$P" run "$HERE/external_read.yaml" -o two --threads 1 --plugin "$plugin" \
                   --participant ramp "${restart[@]}" : \
                   -n 1 "$probe" "$HERE/external_read.yaml" linear "${restart[@]}" > two.log 2>&1
    status=$?
    cat two.log
    [ "$status" -ne 0 ] || fail "a case with output.restart ran with a program without restart writer"
    grep -qF "the external program '$(basename "$probe")' of participant 'probe' (rank 1) did not call set_restart_writer() before initialize()" two.log ||
      fail "the refusal does not name the program and set_restart_writer() before initialize()"
    grep -q "remove output.restart" two.log || fail "the refusal does not say what to do"
    [ ! -e two/restart ] || fail "restart files were written"
    ;;
  *)
    fail "unknown scenario $SCENARIO"
    ;;
esac
echo "PASSED: $SCENARIO"
