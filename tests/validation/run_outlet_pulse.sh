#!/bin/sh
# The outlets' reflection of a pressure pulse (tests/validation/outlet_pulse.py): the
# straight channel (examples/CASE.sph, CASE = channel_inlet_outlet: ny = 10, started with the
# developed profile) built with each outlet type, run with and without the pulse to t = 0.3
# (2.25 L / c0), the probe pressure every 0.005; the check compares the reflection
# coefficients.
#
# Usage: run_outlet_pulse.sh SPHC SOURCE_DIR CASE EXE OUT_DIR [-- CHECK OPTIONS...]
#   (CASE: a scene with the option outlet_type and the parameters ny, start, pulse and
#   dtout, as channel_inlet_outlet; EXE the stem of the solvers' names)
set -eu
. "$(dirname "$0")/common.sh"
scene_args "SPHC SOURCE_DIR CASE EXE OUT_DIR [-- CHECK OPTIONS...]" "$@"
shift 5
[ $# -gt 0 ] && [ "$1" = "--" ] && shift

find_python run_outlet_pulse.sh
fresh_output "$EXE" "$OUT"

RUNS=""
for TYPE in do_nothing mirror characteristic hybrid; do
  echo "== compile: $SPHC $SRC/examples/$CASE.sph -D outlet_type=$TYPE"
  "$SPHC" "$SRC/examples/$CASE.sph" -D outlet_type=$TYPE -o "${EXE}_$TYPE"
  for P in 1 0; do
    echo "== run: ${EXE}_$TYPE --set pulse=$P"
    "${EXE}_$TYPE" --quiet -d "$OUT/${TYPE}_$P" --set ny=10 --set start=1 --set pulse=$P \
      --set dtout=0.005 --tf 0.3
  done
  RUNS="$RUNS $TYPE=$OUT/${TYPE}_1,$OUT/${TYPE}_0"
done
echo "== check: outlet_pulse.py$RUNS $*"
# shellcheck disable=SC2086  # directories without spaces
"$PY" "$SRC/tests/validation/outlet_pulse.py" $RUNS --plot "$OUT/outlet_pulse.png" "$@"
