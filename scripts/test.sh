#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine, builds sphc and runs every test: unit tests (runtime and
# numerics, GoogleTest), compiler tests (lit + FileCheck, error corpus) and the dam-break
# validation against experiment. All through ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup-deps.sh
bash scripts/build.sh
BUILD=${SPHC_BUILD_DIR:-build}
# Generated solvers are cached by content hash; tests use a cache of their own.
export SPHC_CACHE_DIR="$PWD/$BUILD/sphc-cache"
cd "$BUILD"
# The long stability cases (hours in all) run only when asked for: ctest -L stability-long.
if [ $# -eq 0 ]; then set -- -LE stability-long; fi
ctest --output-on-failure -j"$(nproc)" "$@"
