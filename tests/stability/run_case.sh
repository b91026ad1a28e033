#!/bin/sh
# A stability case, in three steps, each of which fails the test when it fails:
#   1. compile the scene with sphc,
#   2. run it, writing its snapshots; the exit status must be one of EXPECT_RC (default 0;
#      "0,3" accepts a run that stopped as a blow-up, exit 3, as long as what it left on disk
#      passes step 3),
#   3. check every snapshot with tests/stability/check_run.py (the invariants: see its
#      docstring).
#
# Usage: run_case.sh SPHC SOURCE_DIR SCENE EXE OUT_DIR [-D NAME=CHOICE...] [RUN OPTIONS...]
#                    [-- CHECK OPTIONS...]
#   SCENE       the scene, relative to SOURCE_DIR (examples/dambreak.sph)
#   EXE         the solver to build
#   OUT_DIR     where the run writes its snapshots (emptied first)
#   -D NAME=CHOICE  compile-time options of the scene
#   RUN OPTIONS passed to the solver; "--dt-factor F" (not a solver option) runs a fixed step
#               of F x DT0, with DT0 given by "--dt0 EXPR" (an awk expression of dx: the
#               scene's fixed step), and "--set dx=V" sets dx for it; "--expect-dt-warning
#               yes|no" (not a solver option either) requires the solver's start-up warning
#               of a fixed step above the stable bound (docs/language.md, Time-step bound)
#               on its standard error, or its absence; "--no-limit-warnings" (nor that)
#               fails the case when the run warns that a quantity left a warn bound of
#               the scene's limits (docs/language.md, Limits): a bundled scene at its
#               defaults must not warn a user
#   CHECK OPTIONS passed to check_run.py after the output directory
# Environment: EXPECT_RC (comma-separated accepted exit codes, default 0); SPHC_PYTHON.
# A run that stops as a blow-up (exit 3) must say on its standard error which output is "the
# last good output".
set -eu

. "$(dirname "$0")/../validation/common.sh"
scene_args "SPHC SOURCE_DIR SCENE EXE OUT_DIR [-D NAME=CHOICE...] [RUN OPTIONS...] \
[-- CHECK OPTIONS...]" "$@"
SCENE=$CASE
shift 5
sphc_options "$@"
shift "$NARGS"
RUN_OPTS=""
DX=""
FACTOR=""
DT0=""
DTWARN=""
NOLIMITWARN=""
while [ $# -gt 0 ] && [ "$1" != "--" ]; do
  case "$1" in
    --dt-factor) FACTOR=$2; shift 2; continue ;;
    --dt0) DT0=$2; shift 2; continue ;;
    --expect-dt-warning) DTWARN=$2; shift 2; continue ;;
    --no-limit-warnings) NOLIMITWARN=yes; shift; continue ;;
    dx=*) DX=${1#dx=} ;;
  esac
  RUN_OPTS="$RUN_OPTS $1"
  shift
done
[ $# -gt 0 ] && shift
if [ -n "$FACTOR" ]; then
  if [ -z "$DT0" ] || [ -z "$DX" ]; then
    echo "run_case.sh: --dt-factor needs --dt0 EXPR and --set dx=V" >&2
    exit 2
  fi
  DT=$(awk -v dx="$DX" -v f="$FACTOR" "BEGIN { printf \"%.17g\", f * ($DT0) }")
  echo "   fixed step: $FACTOR x ($DT0) at dx = $DX: dt = $DT"
  RUN_OPTS="$RUN_OPTS --dt $DT"
fi

find_python run_case.sh
fresh_output "$EXE" "$OUT"

echo "== 1. compile: $SPHC $SRC/$SCENE$SPHC_OPTS -o $EXE"
# shellcheck disable=SC2086  # options are words without spaces
"$SPHC" "$SRC/$SCENE" $SPHC_OPTS -o "$EXE"

echo "== 2. run: $EXE --quiet --timing -d $OUT$RUN_OPTS"
start=$(date +%s)
rc=0
# shellcheck disable=SC2086
"$EXE" --quiet --timing -d "$OUT" $RUN_OPTS 2>"$OUT.stderr" || rc=$?
cat "$OUT.stderr" >&2
echo "   ran in $(( $(date +%s) - start )) s, exit $rc"
case ",${EXPECT_RC:-0}," in
  *",$rc,"*) ;;
  *) echo "FAILED: the run exited $rc (accepted: ${EXPECT_RC:-0})"; exit 1 ;;
esac
if [ -n "$DTWARN" ]; then
  warned=no
  grep -qF "warning: the fixed time step" "$OUT.stderr" && warned=yes
  if [ "$warned" != "$DTWARN" ]; then
    echo "FAILED: the solver's warning of a fixed step above the stable bound: expected" \
         "$DTWARN, got $warned"
    exit 1
  fi
  echo "   start-up warning of a fixed step above the stable bound: $warned (as expected)"
fi
if [ -n "$NOLIMITWARN" ] && grep -q "^warning: .*limit '" "$OUT.stderr"; then
  echo "FAILED: the run warned that it left a warn bound of the scene's limits:"
  grep "^warning: .*limit '" "$OUT.stderr"
  exit 1
fi
if [ "$rc" = 3 ] && ! grep -qF "the last good output is" "$OUT.stderr"; then
  echo "FAILED: the run stopped (exit 3) without naming the last good output"
  exit 1
fi

echo "== 3. check: check_run.py $OUT $*"
"$PY" "$SRC/tests/stability/check_run.py" "$OUT" "$@"
