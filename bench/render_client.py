#!/usr/bin/env python3
"""/v1/render as a client sees it: every example scene (examples/*.json), N requests each on one
kept-alive connection (python http.client; an animated scene, a quarter of N, at least 3),
each with its own scene `time` so that no answer comes from the response cache. Prints the client's p50 / p99 and the p50 of each Server-Timing
entry the server sent (compute, then its stages: scene building, waiting for a render thread,
drawing, read-back, encoding). With a second binary, the same for it in the same run, and the
ratio of the two p50s (the baseline first).

    bench/render_client.py [--requests N] [--examples DIR] BIN [BASELINE_BIN]
"""
import argparse, glob, http.client, json, os, re, statistics, sys, time

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tests"))
import effectd_process  # noqa: E402

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
TIMING = re.compile(r"([A-Za-z]+);dur=([0-9.]+)")


def pct(values, q):
    v = sorted(values)
    return v[min(len(v) - 1, int(q * len(v)))]


def measure(binary, scenes, requests):
    """{example: (client ms list, {timing name: ms list}, renderer)} for one server."""
    proc, port = effectd_process.start(binary, "--access-log", "0")
    out = {}
    try:
        conn = http.client.HTTPConnection("127.0.0.1", port)
        for name, scene in scenes:
            client, stages, renderer = [], {}, ""
            n = max(3, requests // 4) if "frames" in scene else requests
            for i in range(n + 1):  # the first compiles the scene's shader variants
                body = dict(scene, time=scene.get("time", 0.0) + 0.001 * (i + 1))
                t = time.perf_counter()
                conn.request("POST", "/v1/render", body=json.dumps(body), headers={"Content-Type": "application/json"})
                r = conn.getresponse()
                r.read()
                ms = (time.perf_counter() - t) * 1e3
                if r.status != 200:
                    raise SystemExit(f"{binary}: {name} answered {r.status}")
                renderer = r.getheader("X-Renderer", "")
                if i == 0:
                    continue
                client.append(ms)
                for k, v in TIMING.findall(r.getheader("Server-Timing", "")):
                    stages.setdefault(k, []).append(float(v))
            out[name] = (client, stages, renderer)
    finally:
        proc.terminate()
        proc.wait()
    return out


def main():
    a = argparse.ArgumentParser()
    a.add_argument("--requests", type=int, default=20)
    a.add_argument("--examples", default=os.path.join(ROOT, "examples"))
    a.add_argument("binary")
    a.add_argument("baseline", nargs="?")
    args = a.parse_args()
    scenes = [(os.path.basename(p)[:-5], json.load(open(p))) for p in sorted(glob.glob(os.path.join(args.examples, "*.json")))]
    runs = [("baseline", measure(args.baseline, scenes, args.requests))] if args.baseline else []
    runs.append(("this build", measure(args.binary, scenes, args.requests)))
    print(f"renderer: {next(iter(runs[-1][1].values()))[2]}; {args.requests} requests per scene, one kept-alive connection")
    print("| scene | binary | client p50 | client p99 | Server-Timing p50 (ms) |")
    print("|---|---|---|---|---|")
    for name, _ in scenes:
        for label, run in runs:
            client, stages, _ = run[name]
            timing = ", ".join(f"{k} {statistics.median(v):.1f}" for k, v in stages.items())
            print(f"| {name} | {label} | {pct(client, 0.5):.1f} ms | {pct(client, 0.99):.1f} ms | {timing} |")
        if args.baseline:
            base, new = pct(runs[0][1][name][0], 0.5), pct(runs[1][1][name][0], 0.5)
            print(f"| {name} | ratio | {base / new:.2f}x faster | | |")


if __name__ == "__main__":
    main()
