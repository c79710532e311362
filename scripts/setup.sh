#!/usr/bin/env bash
# Installs the Debian 12 packages effectd needs to build, test and run.
# Idempotent: packages already installed are skipped; apt runs only when something is missing.
set -euo pipefail

PACKAGES=(
  build-essential cmake pkg-config git ca-certificates curl
  libcpp-httplib-dev nlohmann-json3-dev libglm-dev
  libopenimageio-dev libegl-dev libgles-dev libegl-mesa0 libgl1-mesa-dri
  zlib1g-dev         # PNGs written in strips on several threads (render/png.cpp)
  libgtest-dev libgmock-dev libbenchmark-dev
  glslang-tools spirv-tools  # every shader variant compiled and validated by each language's own tools
  glslang-dev libspirv-cross-c-shared-dev  # GLSL -> SPIR-V -> HLSL / MSL (server/api/shader_targets.cpp)
  mesa-vulkan-drivers libvulkan-dev  # lavapipe: the SPIR-V drawn by Vulkan on the CPU (tests/vulkan/)
  gnuplot-nox        # plots of the error-against-run-time report (bench/error_report)
  clang-14 libclang-rt-14-dev  # the ASan+UBSan suite and the libFuzzer targets (build-fuzz/)
  iproute2           # ss: tests/binary_test.sh reads the listen backlog
  wrk nginx-light    # scripts/load.sh and the deploy/nginx test (two replicas behind a cache)
  redis-server       # deploy/replicas: API key quotas shared by replicas (--quota-redis)
  godot3-server      # clients/godot: the addon run headless in Godot 3 against a server (tests/godot/)
  godot3 xvfb xauth  # clients/godot: the addon's shaders drawn by Godot 3 on llvmpipe (tests/godot/)
  mono-mcs mono-runtime  # the C API from C# through P/Invoke, as Unity calls native code (tests/capi/)
  assimp-testmodels  # test data: real models (OBJ/glTF) for the tangent oracle tests
  blender            # the second tangent oracle: Blender's own MikkTSpace (tests/mikktspace/blender_oracle.py)
  chromium           # tests/browser: a page on another origin uses effectd (CORS, PNG decode)
  json-schema-test-suite  # the official JSON-Schema tests run against server/contract/schema.cpp
  python3-jsonschema # tests/sweep_test.py checks answers against proto/schemas/*-answer.json
  podman debootstrap # scripts/test-image.sh builds the container image and serves from it
)
# Node.js runs test-only tooling (the MikkTSpace oracle). Machines that already have a node
# (e.g. from NodeSource) keep it; otherwise Debian's.
if ! command -v node >/dev/null || ! command -v npm >/dev/null; then PACKAGES+=(nodejs npm); fi

missing=()
for p in "${PACKAGES[@]}"; do
  if ! dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed"; then
    missing+=("$p")
  fi
done

if [ ${#missing[@]} -eq 0 ]; then
  echo "setup: all ${#PACKAGES[@]} packages present"
else
  echo "setup: installing ${missing[*]}"
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

# three.js for the playground's live view, built into effectd and served from its own origin:
# the version server/playground/vendor/package-lock.json pins, checked against its integrity
# hash by npm ci. Without it effectd still builds, and the playground says its live view is off.
vendor="$(cd "$(dirname "$0")/.." && pwd)/server/playground/vendor"
if [ -d "$vendor" ] && [ ! -f "$vendor/node_modules/three/build/three.module.js" ]; then
  (cd "$vendor" && npm ci --no-audit --no-fund --loglevel=error) ||
    echo "setup: three.js not installed (npm ci failed in $vendor): the playground's live view will be off"
fi
