#!/usr/bin/env bash
# The README's second command: install build dependencies, configure, build, run the whole CTest
# suite. Incremental when run again.
set -euo pipefail
cd "$(dirname "$0")/.."
bash deploy/deps.sh build
BUILD_DIR=${BUILD_DIR:-build}
cmake -S . -B "$BUILD_DIR" -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build "$BUILD_DIR" -j "$(nproc)"
cd "$BUILD_DIR"
ctest --output-on-failure -j "$(nproc)" --timeout 600
