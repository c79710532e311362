#!/usr/bin/env bash
# ctest entry: installs puppeteer-core (npm, pinned by package-lock.json; it downloads no
# browser; three and Babylon.js for the GLB test) and runs a page script (cors.mjs unless named) with Debian's chromium against the
# effectd binary. Usage: run.sh EFFECTD_BINARY [SCRIPT.mjs]
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
command -v node >/dev/null || { echo "node is required: run scripts/setup.sh"; exit 1; }
command -v chromium >/dev/null || { echo "chromium is required: run scripts/setup.sh"; exit 1; }
[ -d "$here/node_modules/puppeteer-core" ] && [ -d "$here/node_modules/three" ] && [ -d "$here/node_modules/@babylonjs/loaders" ] || (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
node "$here/${2:-cors.mjs}" "$1" "$(command -v chromium)"
