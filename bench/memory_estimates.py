#!/usr/bin/env python3
"""Estimated peak memory (what admission control reserves, X-Memory-Reserved) against the
measured peak RSS growth of the process, one request per endpoint and size, each in a fresh
server (so no heap left over by an earlier request hides the growth).

    bench/memory_estimates.py [build/server/effectd]

Measured = VmHWM after the request - VmRSS before it (the kernel's peak is reset first via
/proc/PID/clear_refs). The estimate should be at or above the measurement (ratio >= 1): a
budget built from estimates then bounds the real peak.
"""
import http.client, json, os, sys, time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import effectd_process  # noqa: E402

BIN = sys.argv[1] if len(sys.argv) > 1 else "build/server/effectd"


def grid_mesh(n):
    pos, uv, idx = [], [], []
    for y in range(n + 1):
        for x in range(n + 1):
            pos += [x / n, y / n, 0.1 * ((x * 7 + y * 3) % 5) / n]
            uv += [x / n, y / n]
    for y in range(n):
        for x in range(n):
            a = y * (n + 1) + x
            idx += [a, a + 1, a + n + 1, a + 1, a + n + 2, a + n + 1]
    return {"positions": pos, "uvs": uv, "indices": idx}


def bolt(w, h, method="fast", **kw):
    return dict({"grid": {"width": w, "height": h}, "start": [w // 2, 0], "targets": [[w // 2, h - 1]],
                 "method": method}, **kw)


CASES = [
    ("fog", "/v1/fog", {"fog": {"fogType": "GL_EXP2", "density": 0.05}, "table": {"size": 65536}}),
    ("fog HEIGHT 256x256", "/v1/fog", {"fog": {"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2},
                                        "table": {"size": 256, "elevations": 256}}),
    ("lightning fast 1024^2", "/v1/lightning", bolt(1024, 1024)),
    ("lightning fast 4096^2", "/v1/lightning", bolt(4096, 4096)),
    ("lightning dbm 256^2", "/v1/lightning", bolt(256, 256, "dbm", tolerance=1e-6)),
    ("lightning charges 256^2", "/v1/lightning", bolt(256, 256, "charges")),
    ("tangents 80k tris", "/v1/tangents", {"mesh": grid_mesh(200)}),
    ("bubble mesh level 7", "/v1/bubble", {"include": ["mesh"], "mesh": {"level": 7}}),
    ("bubble thinFilm 1024^2", "/v1/bubble", {"include": ["thinFilm"], "thinFilm": {"width": 1024, "height": 1024}}),
    ("scene lightning 1024^2", "/v1/scene", {"lightning": bolt(1024, 1024)}),
    ("render 1024^2 all", "/v1/render", {"width": 1024, "height": 1024, "lightning": bolt(128, 128),
                                         "fog": {"fog": {"fogType": "GL_EXP", "density": 0.05}},
                                         "bubble": {"params": {}}}),
]


def status_kb(pid, key):
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith(key + ":"):
                return int(line.split()[1])


def start():
    return effectd_process.start(BIN, "--access-log", "0", "--threads", "2", "--response-cache-mb", "0",
                                 "--memory-budget-mb", "100000")


def post(port, path, body):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=600)
    c.request("POST", path, body=json.dumps(body), headers={"Content-Type": "application/json"})
    r = c.getresponse()
    data = r.read()
    return r.status, r.getheader("X-Memory-Reserved"), len(data)


def main():
    print(f"{'request':26} {'estimate MB':>12} {'measured MB':>12} {'est/meas':>9} {'answer MB':>10}")
    worst = 1e9
    for name, path, body in CASES:
        p, port = start()
        try:
            post(port, "/v1/fog", {"fog": {"fogType": "GL_EXP"}})  # warm: code pages, first allocations
            if path == "/v1/render":
                post(port, path, {"width": 8, "height": 8})
            with open(f"/proc/{p.pid}/clear_refs", "w") as f:
                f.write("5")
            before = status_kb(p.pid, "VmRSS")
            status, reserved, size = post(port, path, body)
            peak = status_kb(p.pid, "VmHWM")
            measured = max(peak - before, 1) / 1024
            est = int(reserved or 0) / 2**20
            ratio = est / measured
            worst = min(worst, ratio)
            print(f"{name:26} {est:12.1f} {measured:12.1f} {ratio:9.2f} {size / 2**20:10.2f}" + ("" if status == 200 else f"  status {status}"))
        finally:
            p.terminate()
            p.wait()
    print(f"lowest estimate/measured: {worst:.2f}")


if __name__ == "__main__":
    main()
