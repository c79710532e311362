#!/usr/bin/env bash
# The Godot addon (clients/godot/addons/effectd) against a server this script starts.
#   client_test.sh EFFECTD_BINARY: in Godot 3's headless runtime (godot3-server),
#     clients/godot/tests/run.gd asks for a bolt, fog tables and a bubble, checks the ArrayMesh
#     and ImageTexture it builds against the JSON, that a 400 reaches the game with the field's
#     pointer, and runs the README's snippet.
#   client_test.sh EFFECTD_BINARY render: in Godot 3 itself (godot3, GLES3 on Mesa's llvmpipe
#     under Xvfb), clients/godot/tests/render.gd draws the addon's shaders (the strike, the
#     film, the fog) and checks the pictures.
# Skips (77) where the Godot it needs is not installed (scripts/setup.sh installs both).
set -euo pipefail
# shellcheck source=/dev/null
source "$(dirname "$0")/../listen.sh"
bin=$1
root=$(cd "$(dirname "$0")/../.." && pwd)
mode=${2:-client}
if [ "$mode" = render ]; then
  godot=$(command -v godot3 || true)
  [ -n "$godot" ] && command -v xvfb-run >/dev/null || { echo "SKIP godot3 or xvfb-run not installed (apt install godot3 xvfb)"; exit 77; }
else
  godot=$(command -v godot3-server || true)
  [ -n "$godot" ] || { echo "SKIP godot3-server not installed (apt install godot3-server)"; exit 77; }
fi
work=$(mktemp -d /tmp/effectd-godot.XXXXXX)
pid=""
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT

"$bin" --port 0 --access-log 0 2>"$work/log" &
pid=$!
wait_for_port "$work/log"
# A copy of the project with clients/godot/README.md's snippets in it (each gdscript block,
# tests/readme_snippet_<n>.gd), pointed at this server.
cp -r "$root/clients/godot" "$work/project"
awk -v out="$work/project/tests/readme_snippet_" '/^```gdscript/{on=1; n++; next} /^```/{on=0} on {print > (out n ".gd")}' \
  "$root/clients/godot/README.md"
for f in "$work"/project/tests/readme_snippet_*.gd; do sed -i "s#http://127.0.0.1:8080#http://127.0.0.1:$port#" "$f"; done
grep -q "EffectdClient.bolt(" "$work/project/tests/readme_snippet_1.gd" || { echo "FAIL no bolt snippet in the README"; exit 1; }
grep -q "EffectdClient.bubble(" "$work/project/tests/readme_snippet_2.gd" || { echo "FAIL no bubble snippet in the README"; exit 1; }
# Godot writes its user data under HOME; the locale warnings of a C locale are noise. The exit
# status is Godot's (pipefail).
quiet() { grep -v -e "Unsupported locale" -e "core/translation.cpp" -e "Invalid locale"; }
if [ "$mode" = render ]; then
  HOME="$work" LANG=C.UTF-8 timeout 150 xvfb-run -a -s "-screen 0 640x480x24" "$godot" --path "$work/project" \
    -s res://tests/render.gd --resolution 256x256 --effectd="http://127.0.0.1:$port" 2>&1 | quiet
else
  HOME="$work" LANG=C.UTF-8 timeout 120 "$godot" --path "$work/project" -s res://tests/run.gd \
    --effectd="http://127.0.0.1:$port" 2>&1 | quiet
fi
