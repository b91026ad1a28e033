#!/bin/sh
# rank_failure.sh SPHC periodic_drift.sph: with --set poison=1 the particles right of
# x = 0.9 get u = NaN; the ranks holding them stop (blow-up, exit 3), and sphc::mpi::finish
# ends the whole job with MPI_Abort: mpirun returns non-zero within the timeout (no rank waits
# forever in a collective) and stderr names the failing rank.
set -u
W=$(mktemp -d "${TMPDIR:-/tmp}/sphc-mpi-fail.XXXXXX")
trap 'rm -rf "$W"' EXIT
"$1" "$2" --mpi -o "$W/drift" || exit 1
timeout 120 "${SPHC_MPIRUN:-mpirun}" --allow-run-as-root --oversubscribe -np 2 "$W/drift" \
  --set poison=1 --quiet -d "$W/out" > "$W/log" 2>&1
rc=$?
cat "$W/log"
if [ "$rc" -eq 0 ] || [ "$rc" -eq 124 ]; then
  echo "rank_failure: mpirun returned $rc (0: the failure went unnoticed; 124: a hang)"; exit 1
fi
grep -q "error: rank [01] of 2: " "$W/log" || { echo "rank_failure: no message naming the rank"; exit 1; }
grep -q "simulation blew up" "$W/log" || { echo "rank_failure: no blow-up diagnosis"; exit 1; }
echo "rank_failure: the job stopped (mpirun exit $rc) with the failing rank named"
