#!/usr/bin/env bash
# Installs what is missing, builds everything in Release and runs the whole suite via ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh -DEFFECTD_TESTS=ON -DEFFECTD_BENCH=ON
ctest --test-dir "${BUILD_DIR:-build}" --output-on-failure -j "$(nproc)" "$@"
