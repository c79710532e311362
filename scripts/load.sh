#!/usr/bin/env bash
# Load and soak over loopback with wrk: a mixed load of valid requests against one effectd
# (CONNECTIONS connections, SECONDS seconds), then each route alone as wrk sees it (client-side
# latency distribution), then /v1/fog against nginx serving the same response bytes as a
# static file (wrk -t2 -c16), in the same run. Prints throughput, client-side p50/p90/p99 per
# route beside the server's own histograms, errors, and RSS before/after. Keep-alive latency
# on one connection and cheap-under-heavy figures: bench/serving_bench.py.
#   scripts/load.sh [SECONDS=60] [CONNECTIONS=64]     (build first: scripts/build.sh)
# Exit 1 when a request failed or RSS grew by 10 % or more.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60} connections=${2:-64}
bin=${EFFECTD_BIN:-build/server/effectd}
for tool in wrk nginx curl; do command -v $tool >/dev/null || { echo "$tool missing: run scripts/setup.sh"; exit 1; }; done
work=$(mktemp -d /tmp/effectd-load.XXXXXX)
pids=()
cleanup() { for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done; wait 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT

"$bin" --port 0 --threads 16 --render-queue 64 --access-log 0 >/dev/null 2>"$work/effectd.log" &
pid=$!
pids+=($pid)
for _ in $(seq 100); do grep -q '"listening"' "$work/effectd.log" && break; sleep 0.05; done
port=$(grep -o '"port":[0-9]*' "$work/effectd.log" | head -1 | cut -d: -f2)
url="http://127.0.0.1:$port"
rss() { awk '/VmRSS/ {print $2}' "/proc/$pid/status"; }

# Warm up (render contexts, shader variants, caches), then measure.
wrk -t2 -c8 -d2s -s tests/load/mixed.lua "$url" >/dev/null
before=$(rss)
wrk -t2 -c"$connections" -d"${seconds}s" --timeout 10s --latency -s tests/load/mixed.lua "$url" >"$work/mixed.txt"
after=$(rss)
curl -s "$url/metrics" >"$work/metrics.txt"

rps=$(awk '/Requests\/sec/ {print $2}' "$work/mixed.txt")
non2xx=$(awk '/Non-2xx/ {print $NF}' "$work/mixed.txt"); non2xx=${non2xx:-0}
sockerr=$(awk -F'[ ,]+' '/Socket errors/ {print $4+$6+$8+$10}' "$work/mixed.txt"); sockerr=${sockerr:-0}
echo "mixed load: $connections connections, ${seconds} s, $(awk '/requests in/ {print $1}' "$work/mixed.txt") requests, $rps req/s"
echo "errors: non-2xx $non2xx, socket $sockerr"
echo
printf "%-16s %10s %10s %10s\n" route requests "p50 ms" "p99 ms"
# p50/p99 from the per-route histogram: linear interpolation inside the bucket.
awk '
  /^effectd_http_request_duration_seconds_bucket\{route="\/v1\// {
    match($0, /route="[^"]*"/); r = substr($0, RSTART + 7, RLENGTH - 8)
    match($0, /le="[^"]*"/); le = substr($0, RSTART + 4, RLENGTH - 5)
    n[r]++; b[r, n[r]] = (le == "+Inf" ? 1e9 : le); c[r, n[r]] = $NF
  }
  END {
    for (r in n) {
      total = c[r, n[r]]
      printf "%-16s %10d", r, total
      split("0.5 0.99", qs, " ")
      for (k = 1; k <= 2; k++) {
        want = qs[k] * total; lo = 0; prev = 0
        for (i = 1; i <= n[r]; i++) {
          if (c[r, i] >= want) { hi = b[r, i]; f = (c[r, i] > prev) ? (want - prev) / (c[r, i] - prev) : 0
                                 if (hi > 1e8) hi = lo * 2; printf " %10.2f", (lo + f * (hi - lo)) * 1000; break }
          lo = b[r, i]; prev = c[r, i]
        }
      }
      printf "\n"
    }
  }' "$work/metrics.txt" | sort
echo "(server histograms above; what clients see, each route alone, $connections connections:)"
short=$(( seconds < 15 ? seconds : 15 ))
printf "%-28s %10s %10s %10s %10s\n" "route (client side, wrk)" "req/s" "p50 ms" "p90 ms" "p99 ms"
client_side() {  # name, wrk args...
  local name=$1; shift
  wrk -t2 -c"$connections" -d"${short}s" --latency "$@" >"$work/route.txt"
  awk -v n="$name" '
    function ms(v) { if (v ~ /us$/) return v / 1000; if (v ~ /ms$/) return v + 0; if (v ~ /s$/) return v * 1000; return v }
    /Requests\/sec/ { r = $2 } / 50%/ { a = ms($2) } / 90%/ { b = ms($2) } / 99%/ { c = ms($2) }
    END { printf "%-28s %10.0f %10.2f %10.2f %10.2f\n", n, r, a, b, c }' "$work/route.txt"
}
client_side "GET /healthz" "$url/healthz"
BODY='{"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":256}}' client_side "POST /v1/fog (repeat)" -s tests/load/post.lua "$url/v1/fog"
BODY='{"grid":{"width":128,"height":128},"start":[64,0],"targets":[[64,127]]}' \
  client_side "POST /v1/lightning (repeat)" -s tests/load/post.lua "$url/v1/lightning"
client_side "mixed (tests/load/mixed.lua)" -s tests/load/mixed.lua "$url"
growth=$(awk -v a="$before" -v b="$after" 'BEGIN { printf "%.1f", (b - a) * 100 / a }')
echo
echo "RSS: ${before} kB before, ${after} kB after (${growth} %)"

# /v1/fog against nginx serving the very same bytes as a static file.
body='{"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":256}}'
curl -s -H 'Content-Type: application/json' -d "$body" "$url/v1/fog" >"$work/fog.json"
mkdir -p "$work/www" "$work/tmp"
cp "$work/fog.json" "$work/www/fog.json"
while :; do nport=$((20000 + RANDOM % 20000)); (echo >"/dev/tcp/127.0.0.1/$nport") 2>/dev/null || break; done
user=""
[ "$(id -u)" -eq 0 ] && user="user root root;"
cat >"$work/nginx.conf" <<CONF
worker_processes 1;
pid nginx.pid;
error_log stderr warn;
events { worker_connections 4096; }
http {
  access_log off;
  client_body_temp_path tmp/body; proxy_temp_path tmp/proxy; fastcgi_temp_path tmp/fastcgi;
  uwsgi_temp_path tmp/uwsgi; scgi_temp_path tmp/scgi;
  server { listen 127.0.0.1:$nport; root $work/www; default_type application/json; }
}
CONF
nginx -p "$work" -c "$work/nginx.conf" -g "daemon off; $user" >/dev/null 2>"$work/nginx.log" &
pids+=($!)
for _ in $(seq 100); do curl -sf "http://127.0.0.1:$nport/fog.json" >/dev/null && break; sleep 0.05; done
cmp -s "$work/fog.json" <(curl -s "http://127.0.0.1:$nport/fog.json") || { echo "nginx serves other bytes"; exit 1; }
ours=$(BODY="$body" wrk -t2 -c16 -d"${short}s" -s tests/load/post.lua "$url/v1/fog" | awk '/Requests\/sec/ {print $2}')
theirs=$(wrk -t2 -c16 -d"${short}s" "http://127.0.0.1:$nport/fog.json" | awk '/Requests\/sec/ {print $2}')
echo "/v1/fog (wrk -t2 -c16) $ours req/s vs nginx static file $theirs req/s: ratio $(awk -v a="$ours" -v b="$theirs" 'BEGIN { printf "%.2f", a / b }') (target >= 0.5)"

[ "$non2xx" -eq 0 ] && [ "$sockerr" -eq 0 ] || { echo "FAIL: errors under load"; exit 1; }
awk -v g="$growth" 'BEGIN { exit !(g < 10) }' || { echo "FAIL: RSS grew by $growth %"; exit 1; }
