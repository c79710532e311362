#!/usr/bin/env bash
# Builds the container image (Dockerfile) with podman and serves from it as a cluster would:
# the runtime image's entrypoint, as its non-root user, on a read-only root filesystem with a
# tmpfs /tmp (deploy/k8s: readOnlyRootFilesystem, an emptyDir on /tmp). Checks /healthz,
# /readyz, one request per endpoint, a render, and the image's HEALTHCHECK command; prints the
# image sizes (the runtime image and the full stage it is collected from).
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
  podman build "${args[@]}" -t "$image" . >>"$blog" 2>&1 || { tail -30 "$blog"; say "FAIL: podman build"; exit 1; }
say "built in $(($(date +%s) - start)) s"
size() { podman image inspect --format '{{.Size}}' "$1"; }
say "image size: runtime $(($(size "$image") / 1000000)) MB, full stage $(($(size "$full") / 1000000)) MB"
[ "$(size "$image")" -lt "$(size "$full")" ] || { say "FAIL: the runtime image is not smaller than the full stage"; exit 1; }

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
env -i "${env[@]}" /usr/sbin/chroot --userspec="$user:$user" "$mnt" "${entry[@]}" >"$log" 2>&1 &  # env, chroot exec: $! is effectd
pid=$!
cleanup() { kill "$pid" 2>/dev/null || true; wait "$pid" 2>/dev/null || true; }
trap cleanup EXIT
fail() { say "FAIL: $*"; tail -20 "$log"; exit 1; }
port=$(printf '%s\n' "${env[@]}" | sed -n 's/^EFFECTD_PORT=//p')
base="http://127.0.0.1:$port"
for _ in $(seq 100); do curl -fsS "$base/healthz" >/dev/null 2>&1 && break; sleep 0.1; done
curl -fsS "$base/healthz" >/dev/null || fail "/healthz"
ready=$(curl -fsS "$base/readyz") || fail "/readyz: $ready"
say "/readyz: $ready"
root_opts=$(awk '$5 == "/" { print $6 }' "/proc/$pid/mountinfo")  # as the server sees its root
case "$root_opts" in ro,* | ro) ;; *) fail "the server's root is mounted '$root_opts', not read-only" ;; esac
if as_user /usr/bin/curl -fsS -o /tmp/../probe "$base/healthz" 2>/dev/null; then fail "the server's user could write to /"; fi
for path in /metrics /v1/openapi.yaml /v1/schemas/fog.json; do
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
say "ok: served as user $user from a read-only root: /healthz /readyz /metrics, 5 effect endpoints, a render, HEALTHCHECK"
INNER
