#!/usr/bin/env bash
# Signed URLs from outside, made the ways docs/serving.md shows: the openssl one-liner and the
# kit's effectd-sign.js (Node, Web Crypto), against a server started with a key file; the key
# file rotated and reread on SIGHUP while a client stays connected.
#   signing_test.sh EFFECTD_BINARY
set -euo pipefail
# shellcheck source=/dev/null
source "$(dirname "$0")/../listen.sh"
bin=$1
root=$(cd "$(dirname "$0")/../.." && pwd)
work=$(mktemp -d /tmp/effectd-sign.XXXXXX)
pid=""
cleanup() { [ -n "$pid" ] && kill "$pid" 2>/dev/null; wait 2>/dev/null || true; rm -rf "$work"; }
trap cleanup EXIT
fail() { echo "FAIL $*"; exit 1; }

printf 'first-signing-key-0123456789\n' >"$work/keys.txt"
"$bin" --port 0 --access-log 0 --url-signing-key-file "$work/keys.txt" 2>"$work/log" &
pid=$!
wait_for_port "$work/log"
base="http://127.0.0.1:$port"
status() { curl -s -o /dev/null -w '%{http_code}' "$base$1"; }

# The one-liner of docs/serving.md, word for word but for the key file's name.
r=$(printf '%s' '{"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":64}}' | base64 -w0 | tr '+/' '-_' | tr -d '=')
u="/v1/fog?r=$r&exp=$(( $(date +%s) + 3600 ))"
sig=$(printf '%s' "$u" | openssl dgst -sha256 -hmac "$(head -1 "$work/keys.txt")" -binary | base64 -w0 | tr '+/' '-_' | tr -d '=')
[ "$(status "$u&sig=$sig")" = 200 ] || fail "the documented one-liner's URL: $(status "$u&sig=$sig")"
[ "$(status "$u")" = 403 ] || fail "an unsigned URL is not refused"
[ "$(status "${u}0&sig=$sig")" = 403 ] || fail "a changed exp keeps its signature"
echo "ok   the openssl one-liner signs a URL the server answers; unsigned or altered: 403"

# The kit's signedUrl, in Node.
node --input-type=module -e "
import { webcrypto } from 'node:crypto';
import { signedUrl } from '$root/clients/three/effectd-sign.js';
const scene = { fog: { fogType: 'GL_EXP2', density: 0.05 }, table: { size: 64 } };
console.log(await signedUrl('/v1/fog', scene, 'first-signing-key-0123456789', { expires: Date.now() / 1000 + 60, subtle: webcrypto.subtle }));
console.log(await signedUrl('/v1/fog', scene, 'first-signing-key-0123456789', { expires: Date.now() / 1000 - 60, subtle: webcrypto.subtle }));
" >"$work/urls"
[ "$(status "$(sed -n 1p "$work/urls")")" = 200 ] || fail "the kit's signed URL: $(status "$(sed -n 1p "$work/urls")")"
[ "$(status "$(sed -n 2p "$work/urls")")" = 403 ] || fail "the kit's expired URL is answered"
echo "ok   effectd-sign.js signs in Node; its expired URL is refused"

# Rotation: a second key added, SIGHUP, both sign; the first removed, SIGHUP, only the second.
# A kept-alive client (python http.client) stays connected through both reloads.
python3 - "$port" "$work/keys.txt" "$pid" <<'PY'
import base64, hashlib, hmac, http.client, os, signal, sys, time
port, keys, pid = int(sys.argv[1]), sys.argv[2], int(sys.argv[3])
c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
r = base64.urlsafe_b64encode(b'{"fog":{"fogType":"GL_EXP","density":0.02}}').rstrip(b"=").decode()
def status(key):
    u = f"/v1/fog?r={r}"
    sig = base64.urlsafe_b64encode(hmac.new(key.encode(), u.encode(), hashlib.sha256).digest()).rstrip(b"=").decode()
    c.request("GET", f"{u}&sig={sig}")
    resp = c.getresponse(); resp.read()
    return resp.status
first, second = "first-signing-key-0123456789", "second-signing-key-9876543210"
assert status(first) == 200
def reload(lines):
    open(keys, "w").write("\n".join(lines) + "\n")
    os.kill(pid, signal.SIGHUP)
    time.sleep(0.3)
reload([second, first])
assert (status(second), status(first)) == (200, 200), "both keys sign during the rotation"
reload([second])
assert (status(second), status(first)) == (200, 403), "the old key no longer signs"
print("ok   keys rotated with SIGHUP: both sign, then only the new one; one connection throughout")
PY
grep -q '"key files reread"' "$work/log" || fail "no reload in the log"
echo "urls_signing: passed"
