#!/usr/bin/env bash
# `cmake --install` of the build into a fresh prefix, then an out-of-tree project built against
# it twice, with find_package(effectd CONFIG) (static and shared) and with pkg-config; each
# program's fog table, bolt and tangents must equal the server's answers to the same
# parameters. Also: the shared library's SONAME, the headers and package files, and
# docs/engines.md's C snippet compiled against the prefix, by pkg-config and by its C-only CMake
# project linking the archive.
#   install_test.sh BUILD_DIR EFFECTD_BINARY
set -euo pipefail
# shellcheck source=/dev/null
source "$(dirname "$0")/../listen.sh"
build=$(cd "$1" && pwd)
bin=$2
here=$(cd "$(dirname "$0")" && pwd)
work=$(mktemp -d /tmp/effectd-install.XXXXXX)
pid=""
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "FAIL $*"; exit 1; }

prefix="$work/prefix"
cmake --install "$build" --prefix "$prefix" >"$work/install.log" || { cat "$work/install.log"; fail "cmake --install"; }
lib=$(ls "$prefix"/lib*/libeffects.so.* | head -1)
soname=$(objdump -p "$lib" | awk '/SONAME/ {print $2}')
[[ "$soname" =~ ^libeffects\.so\.[0-9]+$ ]] || fail "SONAME is '$soname'"
# Hidden visibility (effects/export.h): the public headers' functions are exported, nothing
# private (a detail:: namespace, the test hooks of effects/lightning/hooks.h).
exported=$(nm -D --defined-only -C "$lib")
private=$(grep -E 'effects::[a-z:]*detail::|effects::lightning::(solveLaplace|astar|boundaryPotential)' <<<"$exported" || true)
[ -z "$private" ] || fail "libeffects.so exports private symbols: $(head -3 <<<"$private")"
grep -q 'effects::lightning::grow(' <<<"$exported" || fail "libeffects.so does not export effects::lightning::grow"
grep -q ' effects_bolt_grow$' <<<"$exported" || fail "libeffects.so does not export effects_bolt_grow"
echo "ok   exports: $(grep -cE ' (effects::|effects_)' <<<"$exported") effects symbols, none private"
for f in include/effects/lightning.h include/effects/version.h include/effects/export.h; do [ -f "$prefix/$f" ] || fail "$f not installed"; done
ls "$prefix"/lib*/cmake/effectd/effectdConfig.cmake "$prefix"/lib*/cmake/effectd/effectdConfigVersion.cmake \
  "$prefix"/lib*/pkgconfig/effectd.pc >/dev/null || fail "package files"
echo "ok   installed: $(cd "$prefix" && find . -type f | wc -l) files, $soname"

cmake -S "$here/consumer" -B "$work/cmake" -DCMAKE_PREFIX_PATH="$prefix" -DCMAKE_BUILD_TYPE=Release >"$work/cmake.log" 2>&1 ||
  { cat "$work/cmake.log"; fail "find_package(effectd CONFIG)"; }
cmake --build "$work/cmake" -j2 >"$work/build.log" 2>&1 || { cat "$work/build.log"; fail "building against the package"; }
libdir=$(dirname "$lib")
export PKG_CONFIG_PATH="$libdir/pkgconfig"
pkg-config --exists effectd || fail "pkg-config does not find effectd"
# shellcheck disable=SC2046
c++ -std=c++20 -O2 "$here/consumer/consumer.cpp" -o "$work/consumer_pc" $(pkg-config --cflags --libs effectd) 2>"$work/pc.log" ||
  { cat "$work/pc.log"; fail "building with pkg-config"; }
# Captured first: under pipefail, grep -q's early exit can end ldd with SIGPIPE and fail the line.
# Without LD_LIBRARY_PATH: pkg-config's --libs records the run path (docs/engines.md).
loaded=$(env -u LD_LIBRARY_PATH ldd "$work/consumer_pc") || fail "ldd $work/consumer_pc"
found=$(awk '/libeffects\.so/ {print $3}' <<<"$loaded")
[ -n "$found" ] && [ "$(readlink -f "$(dirname "$found")")" = "$(readlink -f "$libdir")" ] ||
  fail "the pkg-config build does not find the installed libeffects.so by itself: $loaded"
echo "ok   built against the prefix: find_package (static, shared) and pkg-config"

# docs/engines.md's C snippet, compiled as C99 against the prefix and run.
root=$(cd "$here/../.." && pwd)
awk '/^```c$/{on=1; next} /^```/{if (on) exit} on' "$root/docs/engines.md" >"$work/snippet.c"
grep -q effects_bolt_grow "$work/snippet.c" || fail "no C snippet in docs/engines.md"
# shellcheck disable=SC2046
cc -std=c99 -Wall -Wextra -pedantic -Werror "$work/snippet.c" -o "$work/snippet" $(pkg-config --cflags --libs effectd) 2>"$work/snippet.log" ||
  { cat "$work/snippet.log"; fail "docs/engines.md's C snippet does not compile"; }
printed=$(env -u LD_LIBRARY_PATH "$work/snippet") || fail "docs/engines.md's C snippet failed (run as built, no LD_LIBRARY_PATH)"
grep -q "^[0-9]* cells$" <<<"$printed" || fail "docs/engines.md's C snippet did not print its cells"
echo "ok   docs/engines.md's C snippet: $printed"
# The same snippet as bolt.c in docs/engines.md's C-only CMake project (its cmake block with
# LANGUAGES C, as printed) linking the archive, effectd::effects: the target carries its C++
# runtime and libm (effects/CMakeLists.txt).
mkdir -p "$work/c_consumer"
cp "$work/snippet.c" "$work/c_consumer/bolt.c"
{
  echo "cmake_minimum_required(VERSION 3.18)"
  awk '/^```cmake$/{on=1; block=""; next} /^```/{if (on && block ~ /LANGUAGES C\)/) {printf "%s", block; exit} on=0} on{block = block $0 "\n"}' \
    "$root/docs/engines.md"
} >"$work/c_consumer/CMakeLists.txt"
grep -q "effectd::effects)" "$work/c_consumer/CMakeLists.txt" || fail "no C-only CMake project in docs/engines.md"
cmake -S "$work/c_consumer" -B "$work/c_build" -DCMAKE_PREFIX_PATH="$prefix" >"$work/c_cmake.log" 2>&1 ||
  { cat "$work/c_cmake.log"; fail "find_package(effectd) from a C-only project"; }
cmake --build "$work/c_build" >"$work/c_build.log" 2>&1 || { tail -20 "$work/c_build.log"; fail "a C-only CMake project does not link effectd::effects"; }
linked=$(ldd "$work/c_build/bolt") || fail "ldd $work/c_build/bolt"
! grep -q libeffects <<<"$linked" || fail "the C-only project linked libeffects.so, not the archive"
printed=$("$work/c_build/bolt") || fail "the C-only project's snippet failed"
echo "ok   a C-only CMake project links effectd::effects (the archive): $printed"

"$bin" --port 0 --access-log 0 2>"$work/log" &
pid=$!
wait_for_port "$work/log"
post() { curl -s -H 'Content-Type: application/json' "http://127.0.0.1:$port$1" -d "$2"; }
post /v1/fog '{"fog":{"fogType":"GL_EXP","density":0.05},"table":{"size":64,"range":[0,100]}}' >"$work/fog.json"
post /v1/lightning '{"grid":{"width":48,"height":48},"start":[24,0],"targets":[[24,47]],"seed":3,"include":["cells"]}' >"$work/bolt.json"
post /v1/tangents '{"mesh":{"positions":[0,0,0, 1,0,0, 1,1,0.2, 0,1,0],"uvs":[0,0, 1,0, 1,1, 0,1],"indices":[0,1,2, 0,2,3]}}' >"$work/tangents.json"
for program in "$work/cmake/consumer_static" "$work/cmake/consumer_shared" "$work/consumer_pc"; do
  LD_LIBRARY_PATH="$libdir" "$program" >"$work/out.json" || fail "$program failed"
  python3 - "$work" "$(basename "$program")" <<'PY' || exit 1
import json, struct, sys
work, name = sys.argv[1], sys.argv[2]
out = json.load(open(f"{work}/out.json"))
f32 = lambda xs: [struct.unpack("f", struct.pack("f", x))[0] for x in xs]
server = {
    "factor": json.load(open(f"{work}/fog.json"))["table"]["factor"],
    "cells": json.load(open(f"{work}/bolt.json"))["cells"],
    "tangents": json.load(open(f"{work}/tangents.json"))["tangents"],
}
for key, theirs in server.items():
    ours = out[key]
    same = ours == theirs if key == "cells" else f32(ours) == f32(theirs)
    if not same:
        print(f"FAIL {name}: {key} differs from the server's ({len(ours)} against {len(theirs)} numbers)")
        sys.exit(1)
print(f"ok   {name}: fog table ({len(out['factor'])} entries), bolt ({len(out['cells']) // 2} cells) and tangents equal the server's")
PY
done
