#!/bin/sh
# Makes reference.npz: PySPH 1.0b1's run of mls_drop.py (nx = 10, 316 particles; fixed
# dt = 5e-6 without the start-up damping; 400 steps to tf = 0.002, a snapshot every 80 steps),
# reduced by compare.py to the fields x, y, u, v, p, rho of every snapshot. Needs PySPH
# (Debian: apt-get install python3-pysph) and h5py.
#   sh tests/lit/Inputs/pysph_mls_drop/make_reference.sh [PYTHON]
set -e
PY=${1:-python3}
HERE=$(cd "$(dirname "$0")" && pwd)
OUT=$(mktemp -d)
$PY "$HERE/mls_drop.py" --nx 10 --no-adaptive-timestep --timestep 5e-6 --n-damp 0 \
    --pfreq 80 -d "$OUT"
$PY "$HERE/compare.py" --pysph-dir "$OUT" --write-reference "$HERE/reference.npz"
rm -rf "$OUT"
