#!/usr/bin/env bash
# A rank of a split bed that stops answering (MpiSubdomainTransport's deadline):
#   stalled_rank.sh MPIRUN PROGRAM
# three ranks step the gravity bed; rank 1 sleeps 100 s before step 40; the transport's deadline
# is 2 s. The run must end non-zero, with a message naming rank 1 as stuck or gone, in well under
# the 100 s of the sleep (the ranks that wait abort; mpirun ends the sleeping one).
set -uo pipefail
MPIRUN=$1
PROGRAM=$2
export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
fail() { echo "FAILED: $*" >&2; exit 1; }
start=$(date +%s)
out=$("$MPIRUN" -n 3 --oversubscribe "$PROGRAM" gravity --deadline 2 --stall 1 40 100 2>&1)
rc=$?
elapsed=$(( $(date +%s) - start ))
echo "$out" | grep -v '^\s*$' | head -20
echo "exit status $rc after $elapsed s"
[ "$rc" -ne 0 ] || fail "the run ended with status 0"
grep -q "rank 1 is stuck or gone" <<< "$out" || fail "no message naming rank 1"
[ "$elapsed" -lt 40 ] || fail "the run took $elapsed s to end (rank 1 slept 100 s)"
echo "ended in $elapsed s, naming rank 1"
