#!/bin/sh
# Validation of the 2D dam break against experiment (Koshizuka & Oka 1996, Martin & Moyce 1952), in three
# steps, each of which fails the test when it fails:
#   1. compile examples/dambreak.sph with sphc,
#   2. run it to t = 1 s, writing snapshots every 0.02 s,
#   3. check the snapshots with dambreak_front.py (finite values, particles in the tank,
#      surge front within 10% of the experimental data; see dambreak_front.py).
#
# Usage: run_dambreak.sh SPHC SOURCE_DIR EXE OUT_DIR
#   SPHC        the sphc executable (<build>/bin/sphc)
#   SOURCE_DIR  the sphc source tree (for examples/ and tests/)
#   EXE         the solver to build (<build>/tests/validation/dambreak)
#   OUT_DIR     where the run writes its snapshots (emptied first)
# The Python interpreter is $SPHC_PYTHON if set, else the first of python3, /usr/bin/python3
# that has numpy and h5py.
set -eu

if [ $# -ne 4 ]; then
  echo "usage: $0 SPHC SOURCE_DIR EXE OUT_DIR" >&2
  exit 2
fi
SPHC=$1
SRC=$2
EXE=$3
OUT=$4

. "$(dirname "$0")/common.sh"
find_python run_dambreak.sh
fresh_output "$EXE" "$OUT"

echo "== 1. compile: $SPHC $SRC/examples/dambreak.sph -o $EXE"
"$SPHC" "$SRC/examples/dambreak.sph" -o "$EXE"

echo "== 2. run: $EXE --tf 1.0 --quiet -d $OUT"
start=$(date +%s)
"$EXE" --tf 1.0 --quiet -d "$OUT"
echo "   ran in $(( $(date +%s) - start )) s"

echo "== 3. check: dambreak_front.py $OUT"
"$PY" "$SRC/tests/validation/dambreak_front.py" "$OUT" --plot "$OUT/front.png"
