#!/usr/bin/env bash
# ctest entry: installs js-yaml (npm, pinned by package-lock.json) and checks deploy/k8s.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
command -v node >/dev/null || { echo "node is required: run scripts/setup.sh"; exit 1; }
[ -d "$here/node_modules/js-yaml" ] || (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
node "$here/check.mjs" "$1" "$here/../.."
