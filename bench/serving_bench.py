#!/usr/bin/env python3
"""What a client sees, measured from the client: keep-alive latency on one connection, and
cheap requests while heavy ones run.

    bench/serving_bench.py [build/server/effectd] [SECONDS=5]

1. One kept-alive connection (python http.client), 200 sequential requests per route:
   p50 / p99 in ms (the Nagle stall made every request after the first take ~44 ms).
2. A 19 800-triangle mesh to /v1/tangents on one connection (--response-cache-mb 0), as JSON
   (1.8 MB) and, as the peer in the same run, as the same mesh in a GLB (0.5 MB):
   client p50 and the p50 of each Server-Timing stage, so the cost of taking JSON is plain.
3. Small uncached fog requests on one connection while 8 dbm 256^2 bolts run, with the
   default heavy-work slots (cores - 1) and, as the baseline in the same run, with
   --heavy-threads 8 (every bolt runs at once, as before the heavy slots existed).
"""
import http.client, json, math, os, statistics, struct, sys, threading, time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import effectd_process  # noqa: E402

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/server/effectd"
SECONDS = float(sys.argv[2]) if len(sys.argv) > 2 else 5


def start(*flags):
    return effectd_process.start(BIN, "--access-log", "0", "--threads", "16", *flags)


def pct(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))]


def timed(conn, method, path, body=None):
    t = time.perf_counter()
    conn.request(method, path, body=body, headers={"Content-Type": "application/json"} if body else {})
    r = conn.getresponse()
    r.read()
    return (time.perf_counter() - t) * 1e3, r.status


def keep_alive(port):
    fog = json.dumps({"fog": {"fogType": "GL_EXP2", "density": 0.05}, "table": {"size": 256}})
    print("keep-alive, one connection, 200 sequential requests (python http.client):")
    print(f"  {'route':34} {'p50 ms':>8} {'p99 ms':>8}")
    for name, method, path, body in [("GET /healthz", "GET", "/healthz", None),
                                     ("POST /v1/fog (cached repeat)", "POST", "/v1/fog", fog),
                                     ("POST /v1/fog (uncached, 256 entries)", "POST", "/v1/fog", None)]:
        c = http.client.HTTPConnection("127.0.0.1", port)
        ms = []
        for i in range(201):
            b = body if body or method == "GET" else json.dumps(
                {"fog": {"fogType": "GL_EXP2", "density": 0.01 + i * 1e-4}, "table": {"size": 256}})
            t, st = timed(c, method, path, b)
            assert st == 200, st
            if i:
                ms.append(t)
        print(f"  {name:34} {statistics.median(ms):8.3f} {pct(ms, 0.99):8.3f}")


def sphere(rings=100, segments=100):
    """A UV sphere: (positions, normals, uvs, indices) as flat lists; 19 800 triangles."""
    pos, nrm, uv, idx = [], [], [], []
    for r in range(rings + 1):
        for s in range(segments + 1):
            th, ph = math.pi * r / rings, 2 * math.pi * s / segments
            st = 0 if r in (0, rings) else math.sin(th)
            p = [st * math.cos(ph), math.cos(th), st * math.sin(ph)]
            pos += p
            nrm += p
            uv += [s / segments, 1 - r / rings]
    row = segments + 1
    for r in range(rings):
        for s in range(segments):
            a = r * row + s
            if r > 0:
                idx += [a, a + 1, a + row]
            if r + 1 < rings:
                idx += [a + 1, a + row + 1, a + row]
    return pos, nrm, uv, idx


def glb(pos, nrm, uv, idx):
    """The mesh as a glTF binary: one primitive, float32 attributes, uint32 indices."""
    parts = [struct.pack(f"<{len(pos)}f", *pos), struct.pack(f"<{len(nrm)}f", *nrm), struct.pack(f"<{len(uv)}f", *uv),
             struct.pack(f"<{len(idx)}I", *idx)]
    views, offset = [], 0
    for part in parts:
        views.append({"buffer": 0, "byteOffset": offset, "byteLength": len(part)})
        offset += len(part)
    n = len(pos) // 3
    accessors = [{"bufferView": 0, "componentType": 5126, "count": n, "type": "VEC3",
                  "min": [min(pos[i::3]) for i in range(3)], "max": [max(pos[i::3]) for i in range(3)]},
                 {"bufferView": 1, "componentType": 5126, "count": n, "type": "VEC3"},
                 {"bufferView": 2, "componentType": 5126, "count": n, "type": "VEC2"},
                 {"bufferView": 3, "componentType": 5125, "count": len(idx), "type": "SCALAR"}]
    doc = {"asset": {"version": "2.0"}, "buffers": [{"byteLength": offset}], "bufferViews": views,
           "accessors": accessors, "scenes": [{"nodes": [0]}], "scene": 0, "nodes": [{"mesh": 0}],
           "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3}]}]}
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    binary = b"".join(parts)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(binary), 0x004E4942) + binary
    return struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks


def mesh_upload(port, rounds=30):
    pos, nrm, uv, idx = sphere()
    as_json = json.dumps({"mesh": {"positions": pos, "normals": nrm, "uvs": uv, "indices": idx}})
    as_glb = glb(pos, nrm, uv, idx)
    print(f"\n/v1/tangents, a {len(idx) // 3}-triangle sphere, one connection, {rounds} requests each, no cache:")
    print(f"  {'body':24} {'bytes':>9} {'client p50':>11}  Server-Timing p50 (ms)")
    p50s = {}
    for name, body, ctype in [("JSON", as_json, "application/json"), ("GLB (peer)", as_glb, "model/gltf-binary")]:
        c = http.client.HTTPConnection("127.0.0.1", port)
        ms, stages = [], {}
        for i in range(rounds + 1):
            t = time.perf_counter()
            c.request("POST", "/v1/tangents", body=body, headers={"Content-Type": ctype})
            r = c.getresponse()
            r.read()
            assert r.status == 200, (name, r.status)
            if i:  # the first warms the heap
                ms.append((time.perf_counter() - t) * 1e3)
                for part in (r.getheader("Server-Timing") or "").split(","):
                    key, _, dur = part.strip().partition(";dur=")
                    if dur:
                        stages.setdefault(key, []).append(float(dur))
        p50s[name] = statistics.median(ms)
        timing = ", ".join(f"{k} {statistics.median(v):.2f}" for k, v in stages.items())
        print(f"  {name:24} {len(body):9d} {p50s[name]:11.2f}  {timing}")
    print(f"  JSON / GLB client p50: {p50s['JSON'] / p50s['GLB (peer)']:.2f}")


def cheap_under_heavy(flags, label):
    p, port = start("--response-cache-mb", "0", *flags)
    stop = time.time() + SECONDS
    done = [0]

    def heavy(k):
        c = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
        i = 0
        while time.time() < stop:
            body = json.dumps({"grid": {"width": 256, "height": 256}, "start": [128, 0], "targets": [[128, 255]],
                               "method": "dbm", "seed": 1000 * k + i})
            timed(c, "POST", "/v1/lightning", body)
            done[0] += 1
            i += 1

    threads = [threading.Thread(target=heavy, args=(k,)) for k in range(8)]
    for t in threads:
        t.start()
    time.sleep(0.3)
    c = http.client.HTTPConnection("127.0.0.1", port)
    ms, i = [], 0
    while time.time() < stop:
        t, st = timed(c, "POST", "/v1/fog", json.dumps({"fog": {"fogType": "GL_EXP", "density": 0.01 + i * 1e-5},
                                                        "table": {"size": 64}}))
        ms.append(t)
        i += 1
        time.sleep(0.002)
    for t in threads:
        t.join()
    p.terminate()
    p.wait()
    print(f"  {label:38} {len(ms):6d} {statistics.median(ms):8.2f} {pct(ms, 0.99):8.2f} {done[0]:8d}")
    return pct(ms, 0.99)


def main():
    p, port = start()
    try:
        keep_alive(port)
    finally:
        p.terminate()
        p.wait()
    p, port = start("--response-cache-mb", "0")
    try:
        mesh_upload(port)
    finally:
        p.terminate()
        p.wait()
    print(f"\nsmall fog requests (64 entries, uncached) while 8 dbm 256^2 bolts run, {SECONDS:.0f} s:")
    print(f"  {'server':38} {'fog n':>6} {'p50 ms':>8} {'p99 ms':>8} {'bolts':>8}")
    ours = cheap_under_heavy([], "heavy slots: cores - 1 (default)")
    base = cheap_under_heavy(["--heavy-threads", "8"], "baseline: --heavy-threads 8")
    print(f"  fog p99 {ours:.2f} ms vs {base:.2f} ms without the slots (target <= 20 ms)")


if __name__ == "__main__":
    main()
