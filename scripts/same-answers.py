#!/usr/bin/env python3
"""Checks that a change kept every answer: starts two effectd binaries (before, after) with
the response cache off and sends both the same requests: every proto/examples request to its
endpoint, every examples/*.json scene to /v1/render, a large tangents mesh in each mode and a
level-6 bubble mesh. JSON answers are compared with their run-time fields removed (elapsedMs,
computeMs and the like differ from run to run); PNGs by their header and pixels (decoded here,
every chunk's CRC and the zlib stream checked: two encoders may write the same pixels in
different bytes); glTF and other answers byte for byte. The memory each request was admitted with
(X-Memory-Reserved: the cost model's estimate and the body's share) must be the same too,
wherever both binaries admitted the request.

  scripts/same-answers.py OLD_EFFECTD NEW_EFFECTD     exit 0 when every answer is the same
"""
import base64, glob, http.client, json, math, os, struct, sys, zlib
sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
from answers import scrub  # noqa: E402
import effectd_process  # noqa: E402


def png_pixels(data):
    """(IHDR fields, unfiltered rows) of a non-interlaced PNG; raises on a bad CRC or stream."""
    assert data[:8] == b"\x89PNG\r\n\x1a\n", "not a PNG"
    at, ihdr, idat = 8, None, b""
    while at < len(data):
        n, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + n]
        assert struct.unpack(">I", data[at + 8 + n:at + 12 + n])[0] == zlib.crc32(kind + body), "bad CRC"
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        at += 12 + n
    w, h, depth, ctype, _, _, interlace = ihdr
    assert interlace == 0, "interlaced"
    bpp = {0: 1, 2: 3, 4: 2, 6: 4}[ctype] * depth // 8
    raw, stride, rows, prev = zlib.decompress(idat), w * bpp, [], bytearray(w * bpp)
    for y in range(h):
        f, row = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = row[i - bpp] if i >= bpp else 0
            b, c = prev[i], prev[i - bpp] if i >= bpp else 0
            p = a + b - c
            pred = [0, a, b, (a + b) // 2,
                    a if abs(p - a) <= abs(p - b) and abs(p - a) <= abs(p - c) else b if abs(p - b) <= abs(p - c) else c][f]
            row[i] = (row[i] + pred) & 0xFF
        rows.append(bytes(row))
        prev = row
    return ihdr, b"".join(rows)


def start(binary):
    return effectd_process.start(binary, "--host", "127.0.0.1", "--response-cache-mb", "0", "--heavy-threads", "2",
                                 "--admission-timeout-ms", "120000")


def post(port, path, body, ctype="application/json"):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=300)
    c.request("POST", path, body=body, headers={"Content-Type": ctype, "Accept-Encoding": "identity"})
    r = c.getresponse()
    data = r.read()
    return r.status, r.getheader("Content-Type", ""), data, r.getheader("X-Memory-Reserved")


def requests():
    for f in sorted(glob.glob("proto/examples/*/*.json")):
        kind = f.split("/")[2]
        if kind != "invalid":
            yield f, f"/v1/{kind}", open(f, "rb").read(), "application/json"
            continue
        case = json.load(open(f))  # {endpoint, body | rawBody | rawBodyBase64 [, contentType], expect}
        if "body" in case:
            body = json.dumps(case["body"]).encode()
        elif "rawBody" in case:
            body = case["rawBody"].encode()
        elif "rawBodyBase64" in case:
            body = base64.b64decode(case["rawBodyBase64"])
        else:
            continue  # generated cases ("generate"): built by tests/examples_test.cpp
        yield f, case["endpoint"], body, case.get("contentType", "application/json")
    for f in sorted(glob.glob("examples/*.json")):
        yield f, "/v1/render", open(f, "rb").read(), "application/json"
    n = 300  # a 180k-triangle wavy grid, every mode
    pos, uv, idx = [], [], []
    for j in range(n + 1):
        for i in range(n + 1):
            x, y = i / n, j / n
            pos += [x, y, 0.1 * math.sin(9 * x) * math.cos(7 * y)]
            uv += [x + 0.05 * math.sin(13 * y), y]
    for j in range(n):
        for i in range(n):
            a = j * (n + 1) + i
            idx += [a, a + 1, a + n + 2, a, a + n + 2, a + n + 1]
    for mode in ("mikktspace", "perTriangle", "perVertex"):
        body = {"mesh": {"positions": pos, "uvs": uv, "indices": idx}, "mode": mode,
                "include": ["tangents", "remap", "indices", "normals"]}
        yield f"grid {n}x{n} {mode}", "/v1/tangents", json.dumps(body).encode(), "application/json"
    for f in sorted(glob.glob("/usr/share/assimp/models/glTF2/*/*.glb")):  # assimp-testmodels
        yield f, "/v1/tangents", open(f, "rb").read(), "model/gltf-binary"
    yield "bubble level 6", "/v1/bubble", json.dumps(
        {"mesh": {"level": 6}, "camera": [0, 0, 4], "time": 3, "include": ["mesh", "uniforms"]}).encode(), "application/json"


def main():
    old, new = start(sys.argv[1]), start(sys.argv[2])
    differ, estimates = 0, 0
    try:
        for name, path, body, ctype in requests():
            a, b = post(old[1], path, body, ctype), post(new[1], path, body, ctype)
            same = a[0] == b[0] and a[1] == b[1]
            if same and "json" in a[1]:
                same = scrub(json.loads(a[2])) == scrub(json.loads(b[2]))
            elif same and a[1] == "image/png":
                same = png_pixels(a[2]) == png_pixels(b[2])
            elif same:
                same = a[2] == b[2]
            estimated = a[3] is not None and b[3] is not None
            estimates += estimated
            if estimated and a[3] != b[3]:
                same = False
                print(f"estimate {a[3]} -> {b[3]} bytes")
            differ += not same
            print(f"{'same' if same else 'DIFFERENT'}  {a[0]}  {path:14} {name}  ({len(b[2])} bytes)")
    finally:
        for p, _ in (old, new):
            p.terminate()
            p.wait()
    print(f"{estimates} memory estimates compared")
    print(f"{differ} answer(s) differ" if differ else "every answer is the same")
    sys.exit(1 if differ else 0)


if __name__ == "__main__":
    main()
