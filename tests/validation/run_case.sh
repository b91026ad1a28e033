#!/bin/sh
# A validation case against an exact or reference solution, in three steps, each of which
# fails the test when it fails:
#   1. compile examples/CASE.sph with sphc,
#   2. run it to the scene's final time, writing its snapshots,
#   3. check the snapshots with tests/validation/CASE.py (which prints a table and the error
#      figures, and writes OUT_DIR/CASE.png).
# Cases: elliptical_drop (exact solution, Monaghan 1994), taylor_green (exact solution,
# periodic), cavity (Ghia et al. 1982), hydrostatic_tank (hydrostatics, Adami et al. 2012),
# the same tank with other schemes (hydrostatic_tank_edac:hydrostatic_tank, ...), dam breaks with other schemes
# against the experiments (dambreak:dambreak_front, dambreak_edac:dambreak_front, ...).
#
# Usage: run_case.sh SPHC SOURCE_DIR CASE EXE OUT_DIR [-D NAME=CHOICE...] [RUN OPTIONS...]
#                    [-- CHECK OPTIONS...]
#   SPHC        the sphc executable (<build>/bin/sphc)
#   SOURCE_DIR  the sphc source tree (for examples/ and tests/)
#   CASE        the case: examples/CASE.sph and tests/validation/CASE.py, or SCENE:CHECK for
#               examples/SCENE.sph checked by tests/validation/CHECK.py (one check, several
#               scenes: hydrostatic_tank_iisph:hydrostatic_tank)
#   EXE         the solver to build (<build>/tests/validation/CASE)
#   OUT_DIR     where the run writes its snapshots (emptied first)
#   -D NAME=CHOICE  a compile-time option of the scene, passed to sphc (e.g. -D scheme=edac:
#               examples/taylor_green.sph built with EDAC); any number, before the run options
#   --global-ids    passed to sphc (the solver writes each particle's gid), before the run options
#   RUN OPTIONS passed to the solver (e.g. --set dx=0.01)
#   CHECK OPTIONS passed to the check after the output directory (e.g. --rho-err-tol 1e-4)
# The Python interpreter is $SPHC_PYTHON if set, else the first of python3, /usr/bin/python3
# that has numpy and h5py.
set -eu

. "$(dirname "$0")/common.sh"
scene_args "SPHC SOURCE_DIR CASE EXE OUT_DIR [-D NAME=CHOICE...] [RUN OPTIONS...] \
[-- CHECK OPTIONS...]" "$@"
shift 5
# Compile-time options first (-D NAME=CHOICE, for sphc), then run options up to "--", check
# options after it.
sphc_options "$@"
shift "$NARGS"
run_options "$@"
shift "$NARGS"

find_python run_case.sh
fresh_output "$EXE" "$OUT"

echo "== 1. compile: $SPHC $SRC/examples/$CASE.sph$SPHC_OPTS -o $EXE"
start=$(date +%s)
# shellcheck disable=SC2086  # options are words without spaces
"$SPHC" "$SRC/examples/$CASE.sph" $SPHC_OPTS -o "$EXE"
echo "   compiled in $(( $(date +%s) - start )) s"

echo "== 2. run: $EXE --quiet --timing -d $OUT$RUN_OPTS"
start=$(date +%s)
# shellcheck disable=SC2086  # options are words without spaces
"$EXE" --quiet --timing -d "$OUT" $RUN_OPTS
echo "   ran in $(( $(date +%s) - start )) s"

echo "== 3. check: $CHECK.py $OUT $*"
"$PY" "$SRC/tests/validation/$CHECK.py" "$OUT" --plot "$OUT/$CASE.png" "$@"
