# Shared by the scripts that build and run scenes for the tests (sourced, POSIX sh):
# tests/validation/run_*.sh, tests/stability/run_case.sh, tests/mpi/*.sh.

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

# mpi_test_setup WHO NAME: what the distributed tests (tests/mpi/*.sh) start with: PY
# (find_python WHO), W a fresh work directory (sphc-NAME.XXXXXX in $TMPDIR or /tmp) removed at
# exit, MPIRUN ($SPHC_MPIRUN, else mpirun).
mpi_test_setup() {
  find_python "$1"
  W=$(mktemp -d "${TMPDIR:-/tmp}/sphc-$2.XXXXXX")
  trap 'rm -rf "$W"' EXIT
  MPIRUN=${SPHC_MPIRUN:-mpirun}
}

# fresh_output EXE OUT: empties the output directory OUT and makes the folder of the solver EXE.
fresh_output() {
  rm -rf "$2"
  mkdir -p "$(dirname "$1")" "$2"
}

# scene_args USAGE ARG...: the five arguments every scene script starts with, SPHC SOURCE_DIR
# CASE EXE OUT_DIR: sets SPHC, SRC, EXE and OUT, and from CASE (SCENE or SCENE:CHECK) CASE to
# the scene and CHECK to the check (the scene's name when CASE names none). With fewer than
# five arguments it prints "usage: SCRIPT USAGE" and exits 2. The caller then drops them
# (shift 5).
scene_args() {
  _usage=$1
  shift
  if [ $# -lt 5 ]; then
    echo "usage: $0 $_usage" >&2
    exit 2
  fi
  SPHC=$1
  SRC=$2
  CASE=${3%%:*}
  CHECK=${3#*:}
  EXE=$4
  OUT=$5
}

# sphc_options ARG...: the compile-time options at the front of ARG... (-D NAME=CHOICE,
# --global-ids, --simd-pairs=MODE, --simd-once-neighbours=N) as the words SPHC_OPTS, to pass
# to sphc; NARGS: how many arguments they took
# (the caller then drops them: shift "$NARGS").
sphc_options() {
  SPHC_OPTS=""
  NARGS=0
  while [ $# -gt 0 ]; do
    case "$1" in
      -D)
        [ $# -gt 1 ] || break
        SPHC_OPTS="$SPHC_OPTS -D $2"
        NARGS=$((NARGS + 2))
        shift 2
        ;;
      --global-ids | --simd-pairs=* | --simd-once-neighbours=*)
        SPHC_OPTS="$SPHC_OPTS $1"
        NARGS=$((NARGS + 1))
        shift
        ;;
      *) break ;;
    esac
  done
}

# run_options ARG...: the solver's options, ARG... up to "--" or the end, as the words
# RUN_OPTS; NARGS: how many arguments to drop, "--" with them, to leave the check's options
# (shift "$NARGS").
run_options() {
  RUN_OPTS=""
  NARGS=0
  while [ $# -gt 0 ] && [ "$1" != "--" ]; do
    RUN_OPTS="$RUN_OPTS $1"
    NARGS=$((NARGS + 1))
    shift
  done
  if [ $# -gt 0 ]; then
    NARGS=$((NARGS + 1))
  fi
}
