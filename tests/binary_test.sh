#!/usr/bin/env bash
# The effectd binary end to end: flags, serving, SIGTERM with a request in flight -> the
# request completes and the process exits 0.
set -euo pipefail
# shellcheck source=/dev/null
source "$(dirname "$0")/listen.sh"
bin="$1"
log=$(mktemp)
trap 'rm -f "$log"; kill %1 2>/dev/null || true' EXIT

"$bin" --help >"$log"  # whole: grep -q would leave the rest unread (SIGPIPE under pipefail)
grep -q -- "--port" "$log"
if "$bin" --port nope 2>/dev/null; then echo "bad flag accepted"; exit 1; fi

# --heavy-threads 8: the eight slow requests below all run at once, as this test intends
# (by default dbm bolts queue for cores - 1 heavy slots; under ASan a queued one would wait
# past --admission-timeout-ms and get 503 before it could be in flight at SIGTERM).
# --shutdown-grace 600: the in-flight requests finish after SIGTERM also under the sanitizers
# (past the default 20 s the process would exit without them).
EFFECTD_THREADS=2 "$bin" --host 127.0.0.1 --port 0 --heavy-threads 8 --shutdown-grace 600 2>"$log" &
pid=$!
wait_for_port "$log"
grep -q '"threads":2' "$log" || { echo "EFFECTD_THREADS ignored"; cat "$log"; exit 1; }

curl -sf "http://127.0.0.1:$port/healthz" | grep -q '"ok"'
# SIGHUP rereads the key files (none here) and the server goes on serving.
kill -HUP "$pid"
for _ in $(seq 100); do grep -q '"key files reread"' "$log" && break; sleep 0.02; done
grep -q '"key files reread"' "$log" || { echo "SIGHUP: no reread"; cat "$log"; exit 1; }
curl -sf "http://127.0.0.1:$port/healthz" | grep -q '"ok"'
# A key file that cannot be read stops the start, naming it (exit 2).
set +e
"$bin" --port 0 --api-keys /nonexistent/keys.json 2>"$log.keys"
rc=$?
set -e
[ "$rc" -eq 2 ] && grep -q '/nonexistent/keys.json' "$log.keys" || { echo "bad key file: exit $rc"; cat "$log.keys"; exit 1; }
rm -f "$log.keys"

# A second effectd on a port in use is an error (cpp-httplib's default SO_REUSEPORT would let
# it bind and silently take half the connections).
if "$bin" --host 127.0.0.1 --port "$port" 2>/dev/null; then echo "a second server bound port $port"; exit 1; fi
# The accept queue is deeper than cpp-httplib's 5 (bursts of new connections overflowed it and
# waited a second for SYN retransmission): ss shows a listener's backlog as Send-Q.
backlog=$(ss -Hltn "sport = :$port" | awk '{print $3}' | head -1)
[ "${backlog:-0}" -ge 128 ] || { echo "listen backlog ${backlog:-?} (want >= 128)"; ss -ltn; exit 1; }

# SIGTERM under load: eight slow requests in flight (DBM bolts with plain CG, and renders);
# once the server has them all, SIGTERM: every one completes with 200 and the process exits 0.
body='{"grid":{"width":96,"height":96},"start":[48,0],"targets":[[48,95]],"method":"dbm","solver":"cg"}'
scene='{"width":256,"height":256,"lightning":{"grid":{"width":64,"height":64},"start":[32,0],"targets":[[32,63]]}}'
curlpids=()
for i in $(seq 8); do
  if [ $((i % 2)) -eq 0 ]; then path=/v1/render data=$scene; else path=/v1/lightning data=$body; fi
  curl -s -o /dev/null -w '%{http_code}' -H 'Content-Type: application/json' \
    -d "$data" "http://127.0.0.1:$port$path" > /tmp/effectd_code.$$.$i &
  curlpids+=($!)
done
for _ in $(seq 200); do  # the metrics request itself is the ninth
  inflight=$(curl -s "http://127.0.0.1:$port/metrics" | awk '/^effectd_http_requests_in_flight/ {print $2}')
  [ "${inflight:-0}" -ge 9 ] && break
  sleep 0.02
done
kill -TERM "$pid"
for c in "${curlpids[@]}"; do wait "$c"; done
set +e
wait "$pid"
rc=$?
set -e
codes=$(cat /tmp/effectd_code.$$.* | tr -d '\n')
rm -f /tmp/effectd_code.$$.*
[ "$rc" -eq 0 ] || { echo "exit code $rc"; cat "$log"; exit 1; }
[ "$codes" = "200200200200200200200200" ] || { echo "in-flight requests got $codes"; cat "$log"; exit 1; }
grep -q '"stopped"' "$log"
grep -q '"path":"/v1/lightning","status":200' "$log" || { echo "no access log line"; cat "$log"; exit 1; }
# The command-line renderer: a scene file to a PNG, no server.
scene=$(dirname "$0")/../examples/01-lightning.json
png=/tmp/effectd_render.$$.png
"$bin" render "$scene" -o "$png" 2>"$log" || { echo "render failed"; cat "$log"; exit 1; }
[ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" = "89504e470d0a1a0a" ] || { echo "not a PNG"; exit 1; }
grep -q '"passes":"background,lightning,blurHorizontal,blurVertical,lightningComposite"' "$log" || { cat "$log"; exit 1; }
rm -f "$png"
echo '{"width": 0}' > /tmp/effectd_bad.$$.json
set +e
"$bin" render /tmp/effectd_bad.$$.json -o "$png" 2>"$log"
rc=$?
set -e
rm -f /tmp/effectd_bad.$$.json
[ "$rc" -eq 2 ] && grep -q '/width' "$log" || { echo "bad scene: exit $rc"; cat "$log"; exit 1; }
[ ! -e "$png" ] || { echo "wrote a PNG for a bad scene"; exit 1; }
# A still scene is a PNG: a .gif name is refused, not filled with PNG bytes.
gif=/tmp/effectd_render.$$.gif
set +e
"$bin" render "$scene" -o "$gif" 2>"$log"
rc=$?
set -e
[ "$rc" -eq 2 ] && grep -q 'renders a PNG' "$log" && [ ! -e "$gif" ] || { echo "still as .gif: exit $rc"; cat "$log"; exit 1; }
# Nor is a .jpg name (the bytes would be PNG under a JPEG name).
set +e
"$bin" render "$scene" -o /tmp/effectd_render.$$.jpg 2>"$log"
rc=$?
set -e
[ "$rc" -eq 2 ] && grep -q 'name the file .png' "$log" && [ ! -e /tmp/effectd_render.$$.jpg ] || { echo "still as .jpg: exit $rc"; cat "$log"; exit 1; }
# A wrong flag says so in one line, not the whole help; a port in use says that.
set +e
"$bin" --no-such-flag 2>"$log"
rc=$?
set -e
[ "$rc" -eq 2 ] && [ "$(wc -l <"$log")" -eq 1 ] && grep -q 'unknown flag --no-such-flag' "$log" || { echo "bad flag: exit $rc"; cat "$log"; exit 1; }
"$bin" --port 0 2>"$log" &
holder=$!
wait_for_port "$log"
set +e
timeout 10 "$bin" --port "$port" 2>"$log"
rc=$?
set -e
kill "$holder"
[ "$rc" -eq 1 ] && grep -q 'the port is in use' "$log" || { echo "port in use: exit $rc"; cat "$log"; exit 1; }
# --version names the build ETags are made from.
"$bin" --version | grep -Eq '^effectd [0-9]+\.[0-9]+\.[0-9]+\+[0-9a-f]+$' || { echo "--version: $("$bin" --version)"; exit 1; }
echo "binary test ok (port $port)"
