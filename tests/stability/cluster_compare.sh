#!/bin/sh
# A scene run with its same-array pair loop in cluster-pair tiles (sphc --simd-pairs=cluster,
# codegen/ClusterPairs.cpp; docs/performance-log.md, "Cluster-pair tiles in the printer (stop
# 37)") and as another --simd-pairs mode prints it, the two runs compared snapshot by
# snapshot (compare_runs.py: positions in dx, density in rho0, velocities). The sums are
# reassociated in the tiles, so the runs differ by round-off that the flow may amplify; the
# limits are the caller's (--max-pos, --max-rho). Fails also where the generated code has no
# loop in tiles (the form stopped applying).
#
# With --omp (stop 38: the tiles under OpenMP, docs/performance-log.md "Cluster-pair tiles under
# OpenMP (stop 38)"): the reference is the serial build's tiles, and the OpenMP build's tiles
# run with 1 and 2 threads must write every snapshot bitwise as the serial run
# (tests/lit/Inputs/restart_bitwise.py: every dataset's bytes and the root attributes); the
# compare_runs.py options are then not used.
#
# Usage: cluster_compare.sh SPHC SOURCE_DIR SCENE EXE OUT_DIR [--other MODE | --omp]
#                           [--sphc-opt OPT]... [RUN OPTIONS...] -- [compare_runs.py OPTIONS...]
#   --other MODE    the reference's --simd-pairs (default once: the lanes each pair once;
#                   since stop 38 auto takes the tiles for 3D loops on the Intel models)
#   --omp           the OpenMP build's tiles at 1 and 2 threads against the serial tiles, bitwise
#   --sphc-opt OPT  an sphc option for both builds (e.g. --simd-once-neighbours=0)
set -eu

. "$(dirname "$0")/../validation/common.sh"
scene_args "SPHC SOURCE_DIR SCENE EXE OUT_DIR [--other MODE] [--sphc-opt OPT]... \
[RUN OPTIONS...] -- [compare_runs.py OPTIONS...]" "$@"
SCENE=$CASE
shift 5
OTHER=once
OMP=0
EXTRA=""
while [ $# -gt 1 ]; do
  case "$1" in
    --other) OTHER=$2; shift 2 ;;
    --omp) OMP=1; shift ;;
    --sphc-opt) EXTRA="$EXTRA $2"; shift 2 ;;
    *) break ;;
  esac
done
run_options "$@"
shift "$NARGS"
find_python cluster_compare
fresh_output "$EXE" "$OUT"
# shellcheck disable=SC2086
if ! "$SPHC" "$SRC/$SCENE" --emit=cpp --simd-pairs=cluster $EXTRA |
    grep -q "both particles in cluster-pair tiles"; then
  echo "cluster_compare: no pair loop of $SCENE in cluster-pair tiles" >&2
  exit 1
fi
# shellcheck disable=SC2086
"$SPHC" "$SRC/$SCENE" --global-ids --simd-pairs=cluster $EXTRA -o "$EXE.cluster"
if [ "$OMP" = 1 ]; then
  # shellcheck disable=SC2086
  if ! "$SPHC" "$SRC/$SCENE" --emit=cpp --simd-pairs=cluster --backend=openmp $EXTRA |
      grep -q "both particles in cluster-pair tiles"; then
    echo "cluster_compare: no pair loop of $SCENE in cluster-pair tiles under OpenMP" >&2
    exit 1
  fi
  # shellcheck disable=SC2086
  "$SPHC" "$SRC/$SCENE" --global-ids --simd-pairs=cluster --backend=openmp $EXTRA -o "$EXE.omp"
  echo "== runs: $EXE.cluster, $EXE.omp --threads 1 and 2 --quiet$RUN_OPTS"
  # shellcheck disable=SC2086
  "$EXE.cluster" --quiet -d "$OUT/cluster" $RUN_OPTS
  for threads in 1 2; do
    # shellcheck disable=SC2086
    "$EXE.omp" --threads "$threads" --quiet -d "$OUT/omp$threads" $RUN_OPTS
    "$PY" "$SRC/tests/lit/Inputs/restart_bitwise.py" "$OUT/cluster" "$OUT/omp$threads"
    # every snapshot of the serial run written by the OpenMP run too
    if [ "$(ls "$OUT/cluster" | grep -c '\.h5$')" != "$(ls "$OUT/omp$threads" | grep -c '\.h5$')" ]; then
      echo "cluster_compare: the OpenMP run with $threads threads wrote other snapshots" >&2
      exit 1
    fi
  done
  exit 0
fi
# shellcheck disable=SC2086
"$SPHC" "$SRC/$SCENE" --global-ids --simd-pairs="$OTHER" $EXTRA -o "$EXE.ref"
echo "== runs: $EXE.{cluster,ref} --quiet$RUN_OPTS"
# shellcheck disable=SC2086
"$EXE.cluster" --quiet -d "$OUT/cluster" $RUN_OPTS
# shellcheck disable=SC2086
"$EXE.ref" --quiet -d "$OUT/ref" $RUN_OPTS
exec "$PY" "$SRC/tests/stability/compare_runs.py" "$OUT/cluster" "$OUT/ref" "$@"
