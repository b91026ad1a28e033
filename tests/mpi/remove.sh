#!/bin/sh
# remove.sh SPHC SRC: a limit's `remove` (docs/language.md, "Limits") on 2 and 3 ranks against
# the serial run (built with --global-ids).
#
#   - The drift (tests/mpi/Inputs/remove_drift.sph, as tests/lit/driver/limits-remove.sph: the
#     top half of a block drifts out over the left wall, 5 particles removed per check, 45 in
#     all, fixed dt): every output equal (tests/mpi/compare_runs.py, 1e-9 of each property's
#     scale), the removed-particles file and the log's `removed` lines equal
#     (tests/mpi/compare_removed.py: by step and gid, all but the rank's index; here
#     exactly, the run has no sums); a 2-rank run stopped at step 50 (--restartable) and
#     restarted on 3 ranks keeps the 20 removed before it and ends with the serial file.
#   - The dam break with walls lower than the column (examples/dambreak.sph, --set dx=0.05
#     --set W=1.5, as the lit test limits-remove-dambreak.sph): water spills over the left
#     wall's top from t = 0.178 s, 5 particles removed to t = 0.26 s (step ~940), with the
#     halo and migration around them: every output (every 0.02 s) within 1e-9 of the serial
#     run's, the removed particles and log lines too. 1e-9 is the other mpi tests' tolerance:
#     the runs differ only by the order of sums (each rank adds its neighbours in its own
#     order), measured at most 2.5e-12 here (fluid.u); a missing or doubled neighbour (a
#     ghost of a removed particle) changes a density by a percent. Later the splash's
#     impact amplifies the rounding (to 7.6e-9 of boundary.p by t = 0.4 s, with the same 9
#     particles removed at the same steps), so the run stops at 0.26 s.
# CI runs as root on 2 cores: mpirun gets --allow-run-as-root --oversubscribe.
set -eu
SPHC=$1; SRC=$2
. "$SRC/tests/validation/common.sh"
mpi_test_setup "mpi remove" mpi-remove
run_mpi() {
  exe=$1; np=$2; shift 2
  timeout 300 "$MPIRUN" --allow-run-as-root --oversubscribe -np "$np" "$exe" --quiet "$@"
}
check() {  # check REF OTHER: outputs, removed particles and log lines
  "$PY" "$SRC/tests/mpi/compare_runs.py" --gid-order "$W/$1" "$W/$2"
  "$PY" "$SRC/tests/mpi/compare_removed.py" "$W/$1" "$W/$2" --log "$W/$1.err" "$W/$2.err"
}

drift=$SRC/tests/mpi/Inputs/remove_drift.sph
"$SPHC" "$drift" --global-ids -o "$W/drift_serial"
"$SPHC" "$drift" --mpi --Werror -o "$W/drift_mpi"
"$W/drift_serial" --quiet -d "$W/ds" 2> "$W/ds.err"
grep -q '^removed: 45 particles' "$W/ds.err"
for np in 2 3; do
  run_mpi "$W/drift_mpi" "$np" -d "$W/dm$np" 2> "$W/dm$np.err"
  echo "== drift, $np ranks"
  check ds "dm$np"
done
run_mpi "$W/drift_mpi" 2 --max-steps 50 --restartable -d "$W/dr" 2> /dev/null
run_mpi "$W/drift_mpi" 3 --restart "$W/dr/s_000050.h5" --restartable -d "$W/dr" 2> "$W/dr.err"
echo "== drift, 2 ranks to step 50, restarted on 3"
grep '^removed at t=0.6.*step 60: 5 particles.* 25 removed so far' "$W/dr.err"
grep '^removed: 45 particles' "$W/dr.err"
"$PY" "$SRC/tests/mpi/compare_removed.py" "$W/ds" "$W/dr"

scene=$SRC/examples/dambreak.sph
args="--set dx=0.05 --set W=1.5 --tf 0.26 --output-every 0.02"
"$SPHC" "$scene" --global-ids -o "$W/db_serial"
"$SPHC" "$scene" --mpi --Werror -o "$W/db_mpi"
# shellcheck disable=SC2086
"$W/db_serial" $args --quiet -d "$W/bs" 2> "$W/bs.err"
grep -q '^removed: 5 particles' "$W/bs.err"
for np in 2 3; do
  # shellcheck disable=SC2086
  run_mpi "$W/db_mpi" "$np" $args -d "$W/bm$np" 2> "$W/bm$np.err"
  echo "== dam break, $np ranks"
  check bs "bm$np"
done
