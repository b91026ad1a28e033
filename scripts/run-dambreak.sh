#!/usr/bin/env bash
# The main job, end to end on a fresh Debian 12 machine: install dependencies, build sphc,
# compile examples/dambreak.sph into a solver, run it to t = 1 s (HDF5 + XDMF output in
# dambreak_output/) and compare its surge front with the experiments.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-deps.sh
bash scripts/build.sh
BUILD=${SPHC_BUILD_DIR:-build}
"$BUILD/bin/sphc" examples/dambreak.sph -o "$BUILD/dambreak" -v
"$BUILD/dambreak" -d dambreak_output "$@"
# The check's Python: $SPHC_PYTHON, else the first of python3, /usr/bin/python3 with numpy
# and h5py (Debian's, which setup-deps.sh installs them for).
. tests/validation/common.sh
find_python run-dambreak.sh
"$PY" tests/validation/dambreak_front.py dambreak_output
