#!/bin/bash
# The image's entrypoint (its default target, Dockerfile): nginx on the public port 8080 in front
# of effectd, which listens on loopback 8081 only; effectd's admin port 9090 (/healthz, /readyz,
# /metrics) is on every address, for probes and Prometheus: publish 8080, keep 9090 inside.
# nginx's configuration is deploy/nginx/pod.conf with edge.conf beside it, as deploy/k8s's sidecar.
# Arguments go to `effectd serve` after these fixed ones (e.g. --api-keys /run/keys.json).
# SIGTERM or SIGINT: nginx stops accepting and finishes the requests it proxies (QUIT), effectd
# answers the ones being computed within --shutdown-grace; the container exits when both have,
# with effectd's status. If either exits on its own, the other is stopped and the container
# exits non-zero, for the runtime to restart it.
set -u
/usr/local/bin/effectd serve --host=127.0.0.1 --port=8081 --admin-host=0.0.0.0 --admin-port=9090 --max-streams-per-address=0 \
  --playground=off "$@" &
effectd=$!
/usr/sbin/nginx -p /tmp/ -e stderr -c /etc/effectd-edge/nginx.conf -g 'daemon off;' &
nginx=$!
stop() {
  kill -QUIT "$nginx" 2>/dev/null
  kill -TERM "$effectd" 2>/dev/null
}
signalled=0
trap 'signalled=1; stop' TERM INT
reap() {  # waits for child $1 through any further signals; returns its status
  local s
  while :; do wait "$1"; s=$?; kill -0 "$1" 2>/dev/null || return "$s"; done
}
first=
wait -n -p first  # the first child to exit (first set), or a signal (first empty)
code=$?
stop
if [ "${first:-}" = "$effectd" ]; then status=$code; else reap "$effectd"; status=$?; fi
[ "${first:-}" = "$nginx" ] || reap "$nginx"
# A child that exited with no signal to the container is a failure, whatever its status.
[ "$signalled" = 0 ] && [ "$status" = 0 ] && status=1
exit "$status"
