#!/usr/bin/env bash
# Two effectd processes behind deploy/nginx/nginx.conf on loopback: both answer the same
# request with the same bytes and ETag, and nginx serves repeats from its cache.
#   test.sh EFFECTD_BINARY
set -euo pipefail
bin=$1
here=$(cd "$(dirname "$0")" && pwd)
command -v nginx >/dev/null || { echo "nginx missing (scripts/setup.sh installs nginx-light)"; exit 1; }
work=$(mktemp -d /tmp/effectd-lb.XXXXXX)
pids=()
cleanup() {
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  wait 2>/dev/null || true
  rm -rf "$work"
}
trap cleanup EXIT

start_effectd() {  # $1 = name; the port is read from its log by port_of
  "$bin" --port 0 --threads 4 --access-log 0 --max-streams-per-address 0 >/dev/null 2>"$work/$1.log" &
  pids+=($!)
}
port_of() {
  for _ in $(seq 100); do grep -q '"listening"' "$work/$1.log" && break; sleep 0.05; done
  grep -o '"port":[0-9]*' "$work/$1.log" | head -1 | cut -d: -f2
}
start_effectd a
start_effectd b
a=$(port_of a)
b=$(port_of b)
[ -n "$a" ] && [ -n "$b" ] || { cat "$work"/*.log; exit 1; }

free_port() {
  while :; do
    p=$((20000 + RANDOM % 20000))
    (echo >"/dev/tcp/127.0.0.1/$p") 2>/dev/null || { echo "$p"; return; }
  done
}
lb=$(free_port)
mkdir -p "$work/tmp" "$work/cache"
sed -e "s/listen 8080;/listen 127.0.0.1:$lb;/" -e "s/127.0.0.1:8081/127.0.0.1:$a/" -e "s/127.0.0.1:8082/127.0.0.1:$b/" \
  "$here/nginx.conf" >"$work/nginx.conf"
cp "$here/edge.conf" "$work/edge.conf"
user=""
[ "$(id -u)" -eq 0 ] && user="user root root;"  # workers must write the cache under $work
nginx -p "$work" -c "$work/nginx.conf" -g "daemon off; $user" >/dev/null 2>"$work/nginx.log" &
pids+=($!)
for _ in $(seq 100); do curl -sf --max-time 2 "http://127.0.0.1:$lb/healthz" >/dev/null && break; sleep 0.05; done

body='{"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":64}}'
post() { curl -s --max-time 20 -D "$work/h.$2" -o "$work/b.$2" -H 'Content-Type: application/json' -d "$body" "http://127.0.0.1:$1/v1/fog"; }
header() { grep -i "^$1:" "$work/h.$2" | cut -d' ' -f2- | tr -d '\r'; }

# The same answer from both replicas, with the same strong ETag.
post "$a" a
post "$b" b
cmp -s "$work/b.a" "$work/b.b" || { echo "replicas differ"; exit 1; }
[ -n "$(header ETag a)" ] && [ "$(header ETag a)" = "$(header ETag b)" ] || { echo "ETags differ"; exit 1; }

# Through nginx: a miss, then hits with the same bytes.
post "$lb" 1
post "$lb" 2
post "$lb" 3
[ "$(header X-Cache-Status 1)" = "MISS" ] || { echo "first: $(header X-Cache-Status 1)"; cat "$work/nginx.log"; exit 1; }
[ "$(header X-Cache-Status 3)" = "HIT" ] || { echo "third: $(header X-Cache-Status 3)"; cat "$work/nginx.log"; exit 1; }
cmp -s "$work/b.1" "$work/b.a" && cmp -s "$work/b.3" "$work/b.a" || { echo "cached body differs"; exit 1; }
[ "$(header ETag 3)" = "$(header ETag a)" ] || { echo "cache lost the ETag"; exit 1; }
# A different body is a different key.
body='{"fog":{"fogType":"GL_EXP2","density":0.06},"table":{"size":64}}'
post "$lb" 4
[ "$(header X-Cache-Status 4)" = "MISS" ] || { echo "different body hit the cache"; exit 1; }
# Conditional requests pass through to a replica: 304 without a body.
code=$(curl -s --max-time 20 -o /dev/null -w '%{http_code}' -H "If-None-Match: $(header ETag a)" -H 'Content-Type: application/json' \
  -d '{"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":64}}' "http://127.0.0.1:$a/v1/fog")
[ "$code" = "304" ] || { echo "If-None-Match gave $code"; exit 1; }
# The public edge (edge.conf): readiness, metrics and the playground are not served; health is.
for path in /readyz /metrics / /index.html; do
  code=$(curl -s --max-time 5 -o /dev/null -w '%{http_code}' "http://127.0.0.1:$lb$path")
  [ "$code" = "404" ] || { echo "$path through nginx: $code, not 404"; exit 1; }
done
code=$(curl -s --max-time 5 -o /dev/null -w '%{http_code}' "http://127.0.0.1:$lb/healthz")
[ "$code" = "200" ] || { echo "/healthz through nginx: $code"; exit 1; }
# A job through nginx: every jobs route reaches the process that took it.
job=$(curl -s --max-time 20 -D - -o /dev/null -H 'Content-Type: application/json' \
  -d '{"effect":"fog","request":{"fog":{"fogType":"GL_EXP2","density":0.08},"table":{"size":16}}}' \
  "http://127.0.0.1:$lb/v1/jobs" | tr -d '\r' | sed -n 's/^Location: //p')
[ -n "$job" ] || { echo "POST /v1/jobs through nginx: no Location"; exit 1; }
for i in $(seq 100); do  # polls until done, each answered by the process that has the job
  code=$(curl -s --max-time 5 -o "$work/job" -w '%{http_code}' "http://127.0.0.1:$lb$job")
  [ "$code" = "200" ] || { echo "GET $job through nginx (poll $i): $code"; exit 1; }
  [ "$i" -ge 4 ] && grep -q '"state":"done"' "$work/job" && break
  sleep 0.05
done
code=$(curl -s --max-time 5 -o /dev/null -w '%{http_code}' "http://127.0.0.1:$lb$job/result")
[ "$code" = "200" ] || { echo "GET $job/result through nginx: $code"; exit 1; }
echo "nginx test ok: replicas on $a and $b agree, cache MISS then HIT through $lb; a job followed through it"
