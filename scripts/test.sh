#!/usr/bin/env bash
# Installs what is missing, builds everything in Release and runs the whole suite via ctest;
# then the same suite built with clang under ASan+UBSan, plus every libFuzzer target for a
# bounded time on its committed seeds (build-fuzz/). EFFECTD_SANITIZE_SUITE=0 skips the second.
# Between the two, scripts/test-image.sh builds the container image and serves from it.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh -DEFFECTD_TESTS=ON -DEFFECTD_BENCH=ON -DEFFECTD_LAB=ON
ctest --test-dir "${BUILD_DIR:-build}" --output-on-failure -j "$(nproc)" "$@"
scripts/test-image.sh  # the container image, served from (skips, saying why, where podman cannot run)

if [ "${EFFECTD_SANITIZE_SUITE:-1}" = 1 ]; then
  CC=clang-14 CXX=clang++-14 BUILD_DIR=build-fuzz BUILD_TYPE=RelWithDebInfo \
    scripts/build.sh -DEFFECTD_FUZZ=ON -DEFFECTD_TESTS=ON -DEFFECTD_BENCH=OFF
  export ASAN_OPTIONS=detect_leaks=1:abort_on_error=0:strict_string_checks=1
  export LSAN_OPTIONS="suppressions=$PWD/tests/lsan.supp:print_suppressions=0"
  export UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
  ctest --test-dir build-fuzz --output-on-failure -j "$(nproc)"
fi
