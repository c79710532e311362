#!/usr/bin/env python3
"""What a client sees, measured from the client: keep-alive latency on one connection, and
cheap requests while heavy ones run.

    bench/serving_bench.py [build/server/effectd] [SECONDS=5]

1. One kept-alive connection (python http.client), 200 sequential requests per route:
   p50 / p99 in ms (the Nagle stall made every request after the first take ~44 ms).
2. Small uncached fog requests on one connection while 8 dbm 256^2 bolts run, with the
   default heavy-work slots (cores - 1) and, as the baseline in the same run, with
   --heavy-threads 8 (every bolt runs at once, as before the heavy slots existed).
"""
import http.client, json, os, statistics, sys, threading, time

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
    print(f"\nsmall fog requests (64 entries, uncached) while 8 dbm 256^2 bolts run, {SECONDS:.0f} s:")
    print(f"  {'server':38} {'fog n':>6} {'p50 ms':>8} {'p99 ms':>8} {'bolts':>8}")
    ours = cheap_under_heavy([], "heavy slots: cores - 1 (default)")
    base = cheap_under_heavy(["--heavy-threads", "8"], "baseline: --heavy-threads 8")
    print(f"  fog p99 {ours:.2f} ms vs {base:.2f} ms without the slots (target <= 20 ms)")


if __name__ == "__main__":
    main()
