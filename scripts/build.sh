#!/usr/bin/env bash
# Configures and builds sphc in ./build (or $SPHC_BUILD_DIR).
set -euo pipefail
cd "$(dirname "$0")/.."
BUILD=${SPHC_BUILD_DIR:-build}
cmake -S . -B "$BUILD" -DCMAKE_BUILD_TYPE=Release >/dev/null
cmake --build "$BUILD" -j"$(nproc)"
