#!/bin/sh
# delta-SPH in the hydrostatic tank: compile examples/hydrostatic_tank.sph, run it with
# alpha = 0.1 without and with the delta-SPH density diffusion (delta = 0.1), and compare the
# pressure noise (tests/validation/delta_sph_tank.py). Fails at the first step that fails.
# Usage: run_delta_tank.sh SPHC SOURCE_DIR EXE OUT_DIR
set -eu
SPHC=$1
SRC=$2
EXE=$3
OUT=$4
PY=""
for cand in ${SPHC_PYTHON:-} python3 /usr/bin/python3; do
  if command -v "$cand" >/dev/null 2>&1 && "$cand" -c "import numpy, h5py" >/dev/null 2>&1; then
    PY=$cand
    break
  fi
done
if [ -z "$PY" ]; then
  echo "run_delta_tank.sh: no Python with numpy and h5py (set SPHC_PYTHON)" >&2
  exit 1
fi
rm -rf "$OUT"
mkdir -p "$(dirname "$EXE")" "$OUT"
echo "== 1. compile"
"$SPHC" "$SRC/examples/hydrostatic_tank.sph" -o "$EXE"
echo "== 2. run without delta-SPH (alpha = 0.1)"
"$EXE" --quiet --timing -d "$OUT/without" --set alpha=0.1 --set delta=0
echo "== 3. run with delta-SPH (alpha = 0.1, delta = 0.1)"
"$EXE" --quiet --timing -d "$OUT/with" --set alpha=0.1 --set delta=0.1
echo "== 4. check"
"$PY" "$SRC/tests/validation/delta_sph_tank.py" "$OUT/without" "$OUT/with" \
  --plot "$OUT/delta_sph_tank.png"
