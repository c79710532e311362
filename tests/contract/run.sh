#!/usr/bin/env bash
# ctest entry: third-party tools against proto/ and the running server. Installs the npm
# packages pinned by package-lock.json (test-only), then:
#   1. @redocly/cli lint (recommended rules; redocly.yaml turns off only what does not apply);
#   2. openapi-typescript generates types from the document and tsc --strict compiles a client
#      that calls every route (client.ts), which contract.mjs runs against the server;
#   3. contract.mjs: answers and problems against their JSON Schemas with ajv, statuses and
#      headers against the document, the hostile corpus against the request schemas.
set -euo pipefail
here="$(cd "$(dirname "$0")" && pwd)"
binary="$1"
command -v node >/dev/null || { echo "node is required: run scripts/setup.sh"; exit 1; }
cd "$here"
[ -d node_modules/ajv ] || npm ci --no-audit --no-fund --loglevel=error
npx --no-install redocly lint --config redocly.yaml ../../proto/openapi.yaml
npx --no-install openapi-typescript ../../proto/openapi.yaml --default-non-nullable false -o generated/effectd-api.d.ts
npx --no-install tsc -p tsconfig.json
echo '{"type": "module"}' > generated/js/package.json
node contract.mjs "$binary"
