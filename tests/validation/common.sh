# Shared by the run_*.sh validation scripts (sourced, POSIX sh).

# find_python WHO: sets PY to the Python interpreter for the checks: $SPHC_PYTHON if set, else
# the first of python3, /usr/bin/python3 that has numpy and h5py. Exits 1, naming WHO, if none.
find_python() {
  PY=""
  for cand in ${SPHC_PYTHON:-} python3 /usr/bin/python3; do
    if command -v "$cand" >/dev/null 2>&1 && "$cand" -c "import numpy, h5py" >/dev/null 2>&1; then
      PY=$cand
      return 0
    fi
  done
  echo "$1: no Python with numpy and h5py (set SPHC_PYTHON)" >&2
  exit 1
}

# fresh_output EXE OUT: empties the output directory OUT and makes the folder of the solver EXE.
fresh_output() {
  rm -rf "$2"
  mkdir -p "$(dirname "$1")" "$2"
}
