#!/bin/sh
# Makes reference.npz: PySPH 1.0b1's run of its example elliptical_drop_no_scheme.py at the
# resolution and step of tests/validation/pysph_elliptical_drop.py's comparison (nx = 20,
# 1,257 particles; fixed dt = 5e-6 without the start-up damping; a snapshot every 40 steps to
# tf = 0.0076), reduced by that script to the observables at every snapshot and the fields at
# t = 0.0008, 0.0038, 0.0076. Needs PySPH (Debian: apt-get install python3-pysph) and h5py.
#   sh tests/data/pysph_elliptical_drop/make_reference.sh [PYTHON]
set -e
PY=${1:-python3}
HERE=$(cd "$(dirname "$0")" && pwd)
OUT=$(mktemp -d)
EX=$($PY -c 'import os, pysph.examples as e; print(os.path.dirname(e.__file__))')
$PY "$EX/elliptical_drop_no_scheme.py" --nx 20 --no-adaptive-timestep --timestep 5e-6 \
    --n-damp 0 --pfreq 40 -d "$OUT"
$PY "$HERE/../../validation/pysph_elliptical_drop.py" --pysph-dir "$OUT" \
    --write-reference "$HERE/reference.npz"
rm -rf "$OUT"
