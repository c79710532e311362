#!/usr/bin/env python3
"""A soak across replicas: three effectd behind deploy/replicas/nginx.conf with one Redis (AOF), as
README.md runs them, under mixed synchronous and job traffic from several API keys for SECONDS
(default 60). Half-way, one replica is SIGKILLed and started again on its ports. Then the
clients stop submitting and every job is followed to its end (at most 120 s more).

Prints, and with --json writes: requests and their statuses, client latency p50 / p99 (all, and
per route), jobs submitted, completed, failed, run again (seen on two workers, or back in the
queue after running) and lost (submitted, and never done nor failed: must be 0), and each
process's RSS before the traffic and after it. Exits 1 if a job is lost or a job's answer is
wrong (no cells). docs/reliability.md holds its figures.

    deploy/replicas/soak.py build/server/effectd [--seconds 60] [--json soak.json]
"""
import argparse
import http.client
import json
import os
import random
import shutil
import signal
import statistics
import sys
import tempfile
import threading
import time

from cluster import Cluster, rss_mib

KEYS = {f"studio-{c}": f"soak-secret-{c}" for c in "abc"}
SYNC_CLIENTS, JOB_CLIENTS = 6, 3


def sync_request(rng):
    """One synchronous request of the mix, its parameters drawn so that most are computed."""
    pick = rng.random()
    if pick < 0.35:
        return "/v1/fog", {"fog": {"fogType": "GL_EXP2", "density": round(rng.uniform(0.01, 0.5), 4)},
                           "table": {"size": 256}}
    if pick < 0.65:
        n = rng.choice([64, 128])
        return "/v1/lightning", {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n - 1]],
                                 "seed": rng.randrange(1, 10**6)}
    if pick < 0.8:
        return "/v1/bubble", {"time": round(rng.uniform(0, 60), 3), "include": ["uniforms", "shader"]}
    if pick < 0.95:
        w = rng.uniform(1, 3)
        return "/v1/tangents", {"mesh": {"positions": [0, 0, 0, w, 0, 0, w, 1, 0, 0, 1, 0], "uvs": [0, 0, 1, 0, 1, 1, 0, 1],
                                         "indices": [0, 1, 2, 0, 2, 3]}}
    return "/v1/render", {"width": 64, "height": 64, "fog": {"fog": {"fogType": "GL_EXP", "density": round(rng.uniform(0.05, 0.3), 4)}},
                          "quads": [{"center": [0, 0, 0], "size": [2, 2]}]}


def job_request(rng):
    """A DBM bolt to a grounded bottom row, as a game bakes a hero bolt (1 to 3 s here)."""
    n = rng.choice([192, 256, 320])
    return {"effect": "lightning", "request": {
        "grid": {"width": n, "height": n}, "method": "dbm", "neighbourhood": 4, "start": [n // 2, 0],
        "targetRegion": {"rows": [{"y": n - 1, "runs": [[0, n]]}]}, "seed": rng.randrange(1, 10**6)}}


class Client:
    """A kept-alive connection to nginx that reconnects after a failure (counted as status 0)."""

    def __init__(self, port, secret):
        self.port, self.conn = port, None
        self.headers = {"Authorization": "Bearer " + secret, "Content-Type": "application/json"}

    def call(self, method, path, body=None):
        try:
            if self.conn is None:
                self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=60)
            self.conn.request(method, path, body=None if body is None else json.dumps(body), headers=self.headers)
            r = self.conn.getresponse()
            data = r.read()
            if r.getheader("Connection", "").lower() == "close":
                self.conn.close()
                self.conn = None
            return r.status, r, data
        except (OSError, http.client.HTTPException):
            if self.conn:
                self.conn.close()
            self.conn = None
            return 0, None, b""


def percentile(values, q):
    if not values:
        return float("nan")
    values = sorted(values)
    return values[min(len(values) - 1, int(q * len(values)))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("binary")
    parser.add_argument("--seconds", type=float, default=60)
    parser.add_argument("--json", help="write the figures here")
    args = parser.parse_args()
    for tool in ("nginx", "redis-server"):
        if not shutil.which(tool):
            print(f"{tool} missing (scripts/setup.sh installs it)")
            return 1
    work = tempfile.mkdtemp(prefix="effectd-soak.")
    cluster = Cluster(args.binary, work, KEYS, "soak-signing-key-0123456789", key_quota=lambda k: (600000, 60000))
    lock = threading.Lock()
    calls = []            # (route, status, seconds, phase)
    jobs = {}             # job path -> {"states": [...], "workers": set(), "end": state, "cells": n}
    stop_submitting = threading.Event()
    phase = ["before"]    # "before" / "after" the kill
    try:
        cluster.start_redis()
        if not cluster.start_replicas(3) or not cluster.start_nginx():
            print("the cluster did not start\n" + cluster.logs())
            return 1
        names = [f"effectd{i}" for i in range(3)]
        rss_before = {n: rss_mib(cluster.procs[n].pid) for n in names + ["redis", "nginx"]}
        secrets = list(KEYS.values())

        def sync_client(k):
            rng = random.Random(k)
            client = Client(cluster.lb, secrets[k % len(secrets)])
            while not stop_submitting.is_set():
                route, body = sync_request(rng)
                t = time.perf_counter()
                status, _, _ = client.call("POST", route, body)
                with lock:
                    calls.append((route, status, time.perf_counter() - t, phase[0]))

        def job_client(k):
            rng = random.Random(1000 + k)
            client = Client(cluster.lb, secrets[k % len(secrets)])
            while not stop_submitting.is_set():
                t = time.perf_counter()
                status, r, _ = client.call("POST", "/v1/jobs", job_request(rng))
                with lock:
                    calls.append(("POST /v1/jobs", status, time.perf_counter() - t, phase[0]))
                if status != 202:
                    time.sleep(0.5)
                    continue
                path = r.getheader("Location")
                record = {"states": [], "workers": set(), "end": None, "cells": 0, "submitted": time.monotonic()}
                with lock:
                    jobs[path] = record
                deadline = time.monotonic() + args.seconds + 120
                while time.monotonic() < deadline:
                    t = time.perf_counter()
                    status, _, data = client.call("GET", path)
                    with lock:
                        calls.append(("GET /v1/jobs/{id}", status, time.perf_counter() - t, phase[0]))
                    if status == 200:
                        state = json.loads(data)
                        if not record["states"] or record["states"][-1] != state["state"]:
                            record["states"].append(state["state"])
                        if state.get("worker"):
                            record["workers"].add(state["worker"])
                        if state["state"] == "running":
                            record["worker"] = state.get("worker")
                        if state["state"] in ("done", "failed", "cancelled"):
                            record["end"] = state["state"]
                            record["took"] = time.monotonic() - record["submitted"]
                            break
                    time.sleep(0.25)
                if record["end"] == "done":
                    status, _, data = client.call("GET", path + "/result")
                    record["cells"] = json.loads(data).get("cellCount", 0) if status == 200 else 0
                    record["resultStatus"] = status

        threads = [threading.Thread(target=sync_client, args=(k,)) for k in range(SYNC_CLIENTS)]
        threads += [threading.Thread(target=job_client, args=(k,)) for k in range(JOB_CLIENTS)]
        started = time.monotonic()
        for t in threads:
            t.start()
        time.sleep(args.seconds / 2)
        rss_middle = {n: rss_mib(cluster.procs[n].pid) for n in names + ["redis", "nginx"]}
        # The victim: a replica running a job now (its worker is host:pid:tag), so that the kill
        # loses work in flight; replica 1 if none is.
        pids = {str(cluster.procs[n].pid): i for i, n in enumerate(names)}
        victim_index = 1
        for _ in range(40):
            with lock:
                running = [j["worker"].split(":")[1] for j in jobs.values()
                           if j["end"] is None and j.get("worker") and j["states"][-1:] == ["running"]]
            running = [pids[p] for p in running if p in pids]
            if running:
                victim_index = running[0]
                break
            time.sleep(0.1)
        victim = names[victim_index]
        cluster.kill(victim, signal.SIGKILL)
        killed_at = time.monotonic() - started
        phase[0] = "after"
        restarted = cluster.start_replica(victim_index)
        back_after = time.monotonic() - started - killed_at
        time.sleep(max(0.0, args.seconds - (time.monotonic() - started)))
        stop_submitting.set()
        for t in threads:
            t.join()
        drained = time.monotonic() - started - args.seconds
        rss_after = {n: rss_mib(cluster.procs[n].pid) for n in names + ["redis", "nginx"]}

        statuses = {}
        for _, s, _, _ in calls:
            statuses[str(s)] = statuses.get(str(s), 0) + 1
        routes = {}
        for route, s, secs, _ in calls:
            routes.setdefault(route, []).append(secs * 1000)
        errors_by_phase = {}
        for route, s, _, ph in calls:
            if s >= 400 or s == 0:
                errors_by_phase.setdefault(ph, {}).setdefault(f"{route} {s}", 0)
                errors_by_phase[ph][f"{route} {s}"] += 1
        done = [j for j in jobs.values() if j["end"] == "done"]
        wrong = [p for p, j in jobs.items() if j["end"] == "done" and j["cells"] <= 0]
        again = [p for p, j in jobs.items() if len(j["workers"]) > 1 or "queued" in j["states"][1:]]
        lost = [p for p, j in jobs.items() if j["end"] not in ("done", "failed")]
        figures = {
            "seconds": args.seconds, "syncClients": SYNC_CLIENTS, "jobClients": JOB_CLIENTS, "keys": len(KEYS),
            "victim": victim, "victimWasRunningAJob": bool(running), "killedAt": round(killed_at, 1), "restartedWithin": round(back_after, 2), "restarted": restarted,
            "drainSeconds": round(drained, 1),
            "requests": len(calls), "statuses": dict(sorted(statuses.items())), "errorsByPhase": errors_by_phase,
            "latencyMs": {"all": {"p50": round(percentile([c[2] * 1000 for c in calls], 0.5), 2),
                                  "p99": round(percentile([c[2] * 1000 for c in calls], 0.99), 2)},
                          **{r: {"n": len(v), "p50": round(percentile(v, 0.5), 2), "p99": round(percentile(v, 0.99), 2)}
                             for r, v in sorted(routes.items())}},
            "jobs": {"submitted": len(jobs), "completed": len(done),
                     "failed": sum(j["end"] == "failed" for j in jobs.values()), "runAgain": len(again),
                     "lost": len(lost), "wrongAnswers": len(wrong),
                     "medianCells": statistics.median([j["cells"] for j in done]) if done else 0,
                     "secondsToDone": {"p50": round(percentile([j["took"] for j in done], 0.5), 2),
                                       "max": round(max([j["took"] for j in done], default=0), 2)}},
            # Before the traffic, half-way (the victim just before its kill) and after it (the
            # victim: its new process, started half-way).
            "rssMiB": {n: {"before": round(rss_before[n], 1), "middle": round(rss_middle[n], 1),
                           "after": round(rss_after[n], 1)} for n in rss_before},
        }
        print(json.dumps(figures, indent=1))
        if args.json:
            json.dump(figures, open(args.json, "w"), indent=1)
        if lost or wrong:
            print(f"FAIL: {len(lost)} jobs lost, {len(wrong)} wrong answers: {lost[:5]} {wrong[:5]}")
            for p in lost[:5]:
                print(p, jobs[p])
            return 1
        return 0
    finally:
        cluster.stop()
        shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())
