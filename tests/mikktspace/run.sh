#!/usr/bin/env bash
# ctest entry: installs the oracle (npm, pinned by package-lock.json), starts effectd on an
# ephemeral port, runs oracle.mjs against it with the real model from Debian's
# assimp-testmodels, then gltf.mjs (binary glTF answers: Khronos validator and the oracle).
set -euo pipefail
# shellcheck source=/dev/null
source "$(dirname "$0")/../listen.sh"
bin="$1"
here="$(cd "$(dirname "$0")" && pwd)"
model=/usr/share/assimp/models/OBJ/spider.obj
[ -f "$model" ] || { echo "missing $model: run scripts/setup.sh (package assimp-testmodels)"; exit 1; }
command -v node >/dev/null || { echo "node is required: run scripts/setup.sh"; exit 1; }
if [ ! -d "$here/node_modules/mikktspace" ] || [ ! -d "$here/node_modules/gltf-validator" ]; then
  (cd "$here" && npm ci --no-audit --no-fund --loglevel=error)
fi
log=$(mktemp)
trap 'kill "$pid" 2>/dev/null || true; rm -f "$log"' EXIT
"$bin" --host 127.0.0.1 --port 0 2>"$log" &
pid=$!
wait_for_port "$log"
node "$here/oracle.mjs" "http://127.0.0.1:$port" "$model"
node "$here/gltf.mjs" "http://127.0.0.1:$port"
