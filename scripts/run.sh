#!/usr/bin/env bash
# Installs what is missing, builds in Release and starts effectd on 127.0.0.1:8080.
# Arguments are passed to effectd (e.g. --port 9000 --threads 16); see `effectd --help`.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/setup.sh
scripts/build.sh -DEFFECTD_TESTS=OFF -DEFFECTD_BENCH=OFF
exec "${BUILD_DIR:-build}/server/effectd" "$@"
