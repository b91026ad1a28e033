#!/bin/sh
# restart.sh SPHC SRC SCENE STEPS HALF 'SPHC ARGS' 'SOLVER ARGS': restarts on other rank counts.
#
# Builds SCENE serial with --global-ids and with --mpi. The reference: the serial solver for
# STEPS steps, every output written with --restartable. Then
#   - a 2-rank run stops at step HALF (its last output, written collectively or gathered, in gid
#     order), and runs restarted from that file on 1 and 4 ranks go on to STEPS;
#   - the serial run's own output at HALF (cell order, not gid order) restarted on 2 ranks;
#   - the 2-rank file restarted by the serial solver (--global-ids: it has gid).
# Every output each restarted run writes (those after HALF) must match the reference's file of
# the same step particle by particle, matched by gid (tests/mpi/compare_runs.py: every property
# and constant within 1e-9 of its scale, the same layout, the distributed runs' in gid order),
# as the uninterrupted distributed runs of run_compare.sh do. CI runs as root on 2 cores:
# mpirun gets --allow-run-as-root --oversubscribe.
set -eu
SPHC=$1; SRC=$2; SCENE=$3; STEPS=$4; HALF=$5; SPHC_ARGS=$6; RUN_ARGS=$7
. "$SRC/tests/validation/common.sh"
mpi_test_setup "mpi restart" mpi-restart
run_mpi() {
  np=$1; shift
  # shellcheck disable=SC2086
  timeout 300 "$MPIRUN" --allow-run-as-root --oversubscribe -np "$np" "$W/mpi" $RUN_ARGS \
    --restartable --quiet "$@"
}
# shellcheck disable=SC2086
"$SPHC" "$SCENE" $SPHC_ARGS --global-ids -o "$W/serial"
# shellcheck disable=SC2086
"$SPHC" "$SCENE" $SPHC_ARGS --mpi -o "$W/mpi"
# shellcheck disable=SC2086
"$W/serial" $RUN_ARGS --restartable --max-steps "$STEPS" --quiet -d "$W/ref"
# shellcheck disable=SC2086
"$W/serial" $RUN_ARGS --restartable --max-steps "$HALF" --quiet -d "$W/serial_half"
run_mpi 2 --max-steps "$HALF" -d "$W/np2_half"
half=$(printf '%06d' "$HALF")
from_np2=$(ls "$W"/np2_half/*_"$half".h5)
from_serial=$(ls "$W"/serial_half/*_"$half".h5)

# The reference's files a restarted run must have written: those after HALF.
compare() {  # compare DIR [--gid-order]
  dir=$1; shift
  rm -rf "$W/want"; mkdir "$W/want"
  for f in "$W"/ref/*.h5; do
    step=$(basename "$f" .h5 | sed 's/.*_0*\([0-9]\)/\1/')
    if [ "$step" -gt "$HALF" ]; then ln -s "$f" "$W/want/"; fi
  done
  if [ -z "$(ls "$W/want")" ]; then echo "restart: no reference output after step $HALF"; exit 1; fi
  "$PY" "$SRC/tests/mpi/compare_runs.py" "$@" "$W/want" "$dir"
  extra=$(cd "$dir" && ls ./*.h5 | while read -r f; do [ -e "$W/want/$f" ] || echo "$f"; done)
  if [ -n "$extra" ]; then echo "restart: files the reference does not have: $extra"; exit 1; fi
}
for np in 1 4; do
  run_mpi "$np" --restart "$from_np2" --max-steps "$STEPS" -d "$W/r2to$np"
  echo "== restart of the 2-rank output at step $HALF on $np rank(s)"
  compare "$W/r2to$np" --gid-order
done
run_mpi 2 --restart "$from_serial" --max-steps "$STEPS" -d "$W/rs_to2"
echo "== restart of the serial output at step $HALF on 2 ranks"
compare "$W/rs_to2" --gid-order
# shellcheck disable=SC2086
"$W/serial" $RUN_ARGS --restartable --restart "$from_np2" --max-steps "$STEPS" --quiet -d "$W/r2_serial"
echo "== restart of the 2-rank output at step $HALF by the serial solver"
compare "$W/r2_serial"
