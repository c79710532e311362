#!/usr/bin/env bash
# Builds the container image (Dockerfile) with podman and serves from it as a cluster would:
# the default (edge) image's entrypoint, as its non-root user, on a read-only root filesystem
# with a tmpfs /tmp (deploy/k8s: readOnlyRootFilesystem, an emptyDir on /tmp). Checks, through
# nginx on the public port, /healthz, one request per endpoint and a render; that /readyz,
# /metrics and / are not public but answered on the admin port; that effectd listens on
# loopback only; the image's HEALTHCHECK command; that SIGTERM stops the container with status
# 0, and that effectd dying stops it non-zero. The runtime target (effectd alone) must start
# too. Prints the image sizes (edge, runtime, and the full stage they are collected from).
#
# `podman run` cannot start containers in every sandbox (crun needs rlimits and cgroups), so
# the image's filesystem is mounted (`podman image mount`) and entered with chroot inside new
# mount and network namespaces (unshare): its own loopback, so port 8080 is always free.
# The base image debian:bookworm comes from `debootstrap --variant=minbase` (no registry
# needed), cached by podman under that name.
#
#   scripts/test-image.sh                the binary from ${BUILD_DIR:-build} (scripts/build.sh)
#   scripts/test-image.sh --from-source  the Dockerfile's own build stage (slow: a full build)
# Skips, with a line saying why, where podman, debootstrap or root is missing or podman
# does not work; any failure after those checks fails the script.
set -euo pipefail
cd "$(dirname "$0")/.."
say() { echo "test-image: $*"; }
skip() { say "SKIPPED: $*"; exit 0; }

from_source=0
[ "${1:-}" = --from-source ] && from_source=1
[ "$(id -u)" -eq 0 ] || skip "needs root (chroot, mounts, namespaces)"
command -v podman >/dev/null || skip "podman is not installed (apt-get install podman)"
command -v debootstrap >/dev/null || skip "debootstrap is not installed (apt-get install debootstrap)"
podman info >/dev/null 2>&1 || skip "podman does not work here: $(podman info 2>&1 | tail -1)"
unshare --mount --net true 2>/dev/null || skip "cannot create mount and network namespaces"
# Storage: an image can be imported and mounted (what the checks below stand on).
probe=localhost/effectd-probe:latest
if ! { tar -C "$(mktemp -d)" -c . | podman import -q - "$probe" >/dev/null && podman image mount "$probe" >/dev/null &&
       podman image unmount "$probe" >/dev/null; } 2>/dev/null; then
  podman rmi -f "$probe" >/dev/null 2>&1 || true
  skip "podman cannot import and mount an image here"
fi
podman rmi -f "$probe" >/dev/null 2>&1 || true

image=localhost/effectd:test
runtime=localhost/effectd:test-runtime
full=localhost/effectd:test-full

# 1. The base image, made once from Debian's archive (the mirror apt uses here).
if ! podman image exists docker.io/library/debian:bookworm; then
  mirror=$(cat /etc/apt/sources.list /etc/apt/sources.list.d/*.sources /etc/apt/sources.list.d/*.list 2>/dev/null |
             grep -oE '^(URIs:|deb) +https?://[^ ]+/debian/?( |$)' | head -1 | awk '{print $2}' || true)
  mirror=${mirror:-http://deb.debian.org/debian}
  root=$(mktemp -d)
  say "debootstrap bookworm from $mirror"
  debootstrap --variant=minbase bookworm "$root" "$mirror" >"$root.log" 2>&1 ||
    { rm -rf "$root"; skip "debootstrap from $mirror failed (no Debian archive here?): $(tail -1 "$root.log")"; }
  rm -rf "$root"/var/cache/apt/archives/*.deb "$root"/var/lib/apt/lists/*
  tar -C "$root" -c . | podman import -q - docker.io/library/debian:bookworm >/dev/null
  rm -rf "$root"
fi
podman image exists docker.io/library/debian:bookworm-slim ||  # a real one, if pulled, is kept
  podman tag docker.io/library/debian:bookworm docker.io/library/debian:bookworm-slim

# 2. The image: the runtime stage (what ships) and the full stage (for the size comparison).
args=(--isolation=chroot --format docker -q)
if [ $from_source = 0 ]; then
  bin="${BUILD_DIR:-build}/server/effectd"
  [ -x "$bin" ] || skip "no $bin: run scripts/build.sh first (or --from-source)"
  mkdir -p build/image
  cp "$bin" build/image/effectd
  args+=(--build-arg PREBUILT=1)
fi
start=$(date +%s)
blog=$(mktemp)
podman build "${args[@]}" --target full -t "$full" . >"$blog" 2>&1 &&
  podman build "${args[@]}" --target runtime -t "$runtime" . >>"$blog" 2>&1 &&
  podman build "${args[@]}" -t "$image" . >>"$blog" 2>&1 || { tail -30 "$blog"; say "FAIL: podman build"; exit 1; }
say "built in $(($(date +%s) - start)) s"
size() { podman image inspect --format '{{.Size}}' "$1"; }
say "image size: edge $(($(size "$image") / 1000000)) MB, runtime $(($(size "$runtime") / 1000000)) MB, full stage $(($(size "$full") / 1000000)) MB"
[ "$(size "$image")" -lt "$(size "$full")" ] || { say "FAIL: the edge image is not smaller than the full stage"; exit 1; }
# The runtime target: effectd alone from its closure, as deploy/k8s runs it.
rmnt=$(podman image mount "$runtime")
chroot --userspec=10001:10001 "$rmnt" /usr/local/bin/effectd --help >/dev/null ||
  { podman image unmount "$runtime" >/dev/null; say "FAIL: the runtime image's effectd does not start"; exit 1; }
podman image unmount "$runtime" >/dev/null

inspect() { podman image inspect --format "$1" "$image"; }
user=$(inspect '{{.Config.User}}')
mapfile -t env < <(inspect '{{range .Config.Env}}{{println .}}{{end}}' | grep .)
mapfile -t entry < <(inspect '{{range .Config.Entrypoint}}{{println .}}{{end}}{{range .Config.Cmd}}{{println .}}{{end}}' | grep .)
mapfile -t health < <(inspect '{{range .Config.Healthcheck.Test}}{{println .}}{{end}}' | grep .)
[ "$user" = 10001 ] || { say "FAIL: image user is '$user', deploy/k8s runs as 10001"; exit 1; }
[ "${health[0]:-}" = CMD ] || { say "FAIL: no HEALTHCHECK CMD in the image (${health[*]:-none})"; exit 1; }

mnt=$(podman image mount "$image")
trap 'podman image unmount "$image" >/dev/null 2>&1 || true' EXIT
export mnt user
# 3. Inside new namespaces: the root as the image has it (read-only), /tmp a tmpfs, /proc,
# /sys and /dev from the host; the server is started from the image's entrypoint and env.
unshare --mount --net --fork bash -s -- "${env[@]}" -- "${entry[@]}" -- "${health[@]:1}" <<'INNER'
set -euo pipefail
say() { echo "test-image: $*"; }
env=(); entry=(); health=()
while [ "$1" != -- ]; do env+=("$1"); shift; done; shift
while [ "$1" != -- ]; do entry+=("$1"); shift; done; shift
health=("$@")
ip link set lo up
mount --make-rprivate /
mount -t tmpfs -o size=256m,mode=1777 tmpfs "$mnt/tmp"
mount -t proc proc "$mnt/proc"
mount --rbind /sys "$mnt/sys"
mount --rbind /dev "$mnt/dev"
as_user() { env -i "${env[@]}" /usr/sbin/chroot --userspec="$user:$user" "$mnt" "$@"; }
log=$(mktemp)
start() {  # the image's entrypoint; env, chroot exec: $! is the entrypoint itself
  env -i "${env[@]}" /usr/sbin/chroot --userspec="$user:$user" "$mnt" "${entry[@]}" >"$log" 2>&1 &
  pid=$!
  for _ in $(seq 100); do curl -fsS "$base/healthz" >/dev/null 2>&1 && break; sleep 0.1; done
}
cleanup() { kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; }
trap cleanup EXIT
fail() { say "FAIL: $*"; tail -20 "$log"; exit 1; }
base=http://127.0.0.1:8080 admin=http://127.0.0.1:9090  # deploy/image/edge.sh's ports
start
curl -fsS "$base/healthz" >/dev/null || fail "/healthz through nginx"
ready=$(curl -fsS "$admin/readyz") || fail "/readyz on the admin port: $ready"
say "/readyz: $ready"
root_opts=$(awk '$5 == "/" { print $6 }' "/proc/$pid/mountinfo")  # as the server sees its root
case "$root_opts" in ro,* | ro) ;; *) fail "the server's root is mounted '$root_opts', not read-only" ;; esac
if as_user /usr/bin/curl -fsS -o /tmp/../probe "$base/healthz" 2>/dev/null; then fail "the server's user could write to /"; fi
for path in /metrics /readyz /; do
  code=$(curl -sS -o /dev/null -w '%{http_code}' "$base$path")
  [ "$code" = 404 ] || fail "GET $path on the public port answered $code, not 404"
  [ "$path" = / ] || curl -fsS -o /dev/null "$admin$path" || fail "GET $path on the admin port"
done
# effectd itself listens on loopback only (8081), its admin port on every address.
listen=$(ss -Hltn | awk '{ print $4 }' | sort | tr '\n' ' ')
case " $listen " in *" 127.0.0.1:8081 "*) ;; *) fail "effectd is not on 127.0.0.1:8081 alone: $listen" ;; esac
case " $listen " in *":8081 "*"0.0.0.0:8081"* | *"*:8081"*) fail "effectd listens beyond loopback: $listen" ;; esac
for path in /v1/openapi.yaml /v1/schemas/fog.json; do
  curl -fsS -o /dev/null "$base$path" || fail "GET $path"
done
for effect in fog lightning tangents bubble scene; do
  body=$(ls proto/examples/$effect/*.json | head -1)
  code=$(curl -sS -o /dev/null -w '%{http_code}' -H 'Content-Type: application/json' --data-binary "@$body" "$base/v1/$effect")
  [ "$code" = 200 ] || fail "POST /v1/$effect with $body: HTTP $code"
done
png=$(mktemp)
code=$(curl -sS -o "$png" -w '%{http_code}' -H 'Content-Type: application/json' --data-binary @examples/03-bubble.json "$base/v1/render")
[ "$code" = 200 ] || fail "POST /v1/render: HTTP $code"
[ "$(head -c 8 "$png" | od -An -tx1 | tr -d ' \n')" = 89504e470d0a1a0a ] || fail "/v1/render did not answer a PNG"
say "render: $(stat -c %s "$png") bytes of PNG"
as_user "${health[@]}" >/dev/null || fail "the HEALTHCHECK command (${health[*]}) failed"
[ -d "$mnt/tmp/cache" ] && say "Mesa's shader cache went to /tmp/cache"
# SIGTERM to the container (its entrypoint): nginx and effectd stop, the status is 0.
kill -TERM "$pid"
status=0
timeout 30 tail --pid="$pid" -f /dev/null || fail "the container did not stop within 30 s of SIGTERM"
wait "$pid" || status=$?
[ "$status" = 0 ] || fail "SIGTERM: the container exited with $status"
pgrep -f "effectd serve|nginx" -u "$user" >/dev/null && fail "a process outlived its container"
# effectd dying on its own stops the container, not zero, for the runtime to restart it.
start
pkill -KILL -u "$user" -f "effectd serve"
timeout 10 tail --pid="$pid" -f /dev/null || fail "the container outlived its effectd by 10 s"
status=0
wait "$pid" || status=$?
[ "$status" != 0 ] || fail "the container exited with 0 after effectd was killed"
pgrep -u "$user" nginx >/dev/null && fail "nginx outlived its container"
say "ok: served as user $user from a read-only root through nginx: /healthz, 5 effect endpoints, a render; /readyz and /metrics on the admin port only; effectd on loopback; HEALTHCHECK; SIGTERM exits 0; a dead effectd stops the container ($status)"
INNER
