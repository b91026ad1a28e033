#!/bin/sh
# A distributed run against the serial one: run_compare.sh SPHC SRC SCENE STEPS 'SPHC ARGS'
# 'SOLVER ARGS' NP...
#
# Builds SCENE serial with --global-ids and with --mpi (same other options), runs the serial
# solver and the MPI one under mpirun on each NP for STEPS steps (SOLVER ARGS set the output
# times: every output is compared), and checks (tests/mpi/compare_runs.py) that every output of every run has the
# serial run's particles, matched by global id, with every property and constant within 1e-9
# of its scale. Differences come only from the order of sums (each rank adds its neighbours
# in its own order): measured at most 2e-13 (Taylor-Green, 20 steps) and 3e-16 (dam break,
# 30 steps); a missing or doubled neighbour changes a density by a percent. With --timing,
# every rank's iteration counts (iterated groups) must equal the serial run's.
# CI runs as root on 2 cores: mpirun gets --allow-run-as-root --oversubscribe.
set -eu
SPHC=$1; SRC=$2; SCENE=$3; STEPS=$4; SPHC_ARGS=$5; RUN_ARGS=$6
shift 6
. "$SRC/tests/validation/common.sh"
mpi_test_setup "mpi compare" mpi
# shellcheck disable=SC2086
"$SPHC" "$SCENE" $SPHC_ARGS --global-ids -o "$W/serial"
# shellcheck disable=SC2086
"$SPHC" "$SCENE" $SPHC_ARGS --mpi -o "$W/mpi"
# shellcheck disable=SC2086
"$W/serial" $RUN_ARGS --max-steps "$STEPS" --quiet --timing -d "$W/out_serial" \
  > "$W/serial.txt"
grep '^iterations:' "$W/serial.txt" | sed 's/^/serial /' || true
for np in "$@"; do
  # shellcheck disable=SC2086
  timeout 300 "$MPIRUN" --allow-run-as-root --oversubscribe -np "$np" "$W/mpi" $RUN_ARGS \
    --max-steps "$STEPS" --quiet --timing -d "$W/out_$np" > "$W/np$np.txt"
  echo "== $np ranks"
  "$PY" "$SRC/tests/mpi/compare_runs.py" --gid-order "$W/out_serial" "$W/out_$np"
  ranks=$(grep -c '^timing:.* rank=' "$W/np$np.txt")
  if [ "$ranks" -ne "$np" ]; then
    echo "run_compare: $ranks timing lines for $np ranks"; exit 1
  fi
  # Every rank prints the serial run's iteration statistics (one line per iterated group).
  want=$(grep '^iterations:' "$W/serial.txt" | sort | sed "s/^/$np /" || true)
  if [ -n "$want" ]; then
    got=$(grep '^iterations:' "$W/np$np.txt" | sort | uniq -c | sed 's/^ *//')
    if [ "$got" != "$want" ]; then
      echo "run_compare: iteration counts on $np ranks differ from the serial run's:"
      grep '^iterations:' "$W/np$np.txt"; exit 1
    fi
    echo "iteration counts: equal on all $np ranks and to the serial run's"
  fi
done
