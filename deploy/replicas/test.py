#!/usr/bin/env python3
"""Three effectd replicas behind deploy/replicas/nginx.conf with one Redis, on loopback, measured
from a client (ctest deploy_replicas):

  A. N distinct signed GET URLs, each asked 1 + M times through nginx: every replica's /metrics
     shows each distinct answer computed once in all (hashing: one replica per answer; repeats
     from nginx's cache);
  B. one API key's admissions over T seconds from 4 clients, spread over the replicas, within
     10 % of its quota (burst + perMinute/60 * T) summed over the replicas (Redis);
  C. a replica killed mid-load: the GETs in flight and after are retried by nginx, none fails;
  D. Redis stopped: keyed requests still answered (fail open to per-replica buckets); the job
     routes answer 503;
  F. a job through nginx: submitted, followed by its events and polled, its answer fetched, all
     through nginx (round robin over the replicas: the jobs live in Redis, --jobs-redis), and its
     state the same from every replica; Prefer: respond-async on an effect route is answered at
     once (nginx drops it);
  G. the replica running a job SIGKILLed: its lease runs out, another replica runs the job again
     and the answer is fetched through nginx (never left "running");
  E. the public path: readiness, metrics and the playground are not served through nginx (each
     replica's admin port serves them), and with 2 x --max-connections clients trickling their
     headers to nginx, /healthz through nginx and on a replica's admin port answers at once.

    deploy/replicas/test.py EFFECTD_BINARY
"""
import base64
import hashlib
import hmac
import http.client
import json
import os
import re
import shutil
import signal
import socket
import sys
import tempfile
import threading
import time

from cluster import Cluster

HERE = os.path.dirname(os.path.abspath(__file__))
SIGNING_KEY = "replicas-signing-key-0123456789"
SECRET = "replicas-test-secret"
BAKER = "replicas-baker-secret"  # F's key, whose quota B leaves alone
PER_MINUTE, BURST = 600, 20
MAX_CONNECTIONS = 32  # each replica's --max-connections; E opens twice as many slow connections


def signed(body):
    target = "/v1/fog?r=" + base64.urlsafe_b64encode(json.dumps(body).encode()).rstrip(b"=").decode()
    sig = hmac.new(SIGNING_KEY.encode(), target.encode(), hashlib.sha256).digest()
    return target + "&sig=" + base64.urlsafe_b64encode(sig).rstrip(b"=").decode()


def fog(i):
    return {"fog": {"fogType": "GL_EXP2", "density": 0.01 + 0.001 * i}, "table": {"size": 64}}


def readiness(port):
    """A replica's /readyz on its admin port: (status, its JSON)."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/readyz")
    r = c.getresponse()
    return r.status, json.loads(r.read())


def metric(port, pattern):
    """A counter from a replica's /metrics, on its admin port."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    c.request("GET", "/metrics")
    text = c.getresponse().read().decode()
    m = re.search(re.escape(pattern) + r" ([0-9.e+]+)", text)
    return float(m.group(1)) if m else 0.0


failures = []


def check(ok, what, detail=""):
    print(("ok   " if ok else "FAIL ") + what + ("" if ok else f": {detail}"))
    if not ok:
        failures.append(what)
    return ok


def main():
    binary = sys.argv[1]
    for tool in ("nginx", "redis-server"):
        if not shutil.which(tool):
            print(f"{tool} missing (scripts/setup.sh installs it)")
            return 1
    work = tempfile.mkdtemp(prefix="effectd-replicas.")
    cluster = Cluster(binary, work, {"load": SECRET, "baker": BAKER}, SIGNING_KEY,
                      key_quota=lambda k: (PER_MINUTE, BURST) if k == "load" else (60000, 60000))
    procs, ports, admin = cluster.procs, cluster.ports, cluster.admin
    try:
        cluster.start_redis()
        start_redis = cluster.start_redis
        if not check(cluster.start_replicas(3, "--max-connections", str(MAX_CONNECTIONS)), "three replicas listening",
                     ports):
            return 1
        cluster.start_nginx()
        lb = cluster.lb

        def get(conn, target, headers=None):
            conn.request("GET", target, headers=headers or {})
            r = conn.getresponse()
            r.read()
            return r

        # A. Distinct answers computed once, repeats from the proxy.
        n, m = 24, 3
        conn = http.client.HTTPConnection("127.0.0.1", lb, timeout=30)
        statuses, hits = [], 0
        for i in range(n):
            for k in range(1 + m):
                r = get(conn, signed(fog(i)))
                statuses.append(r.status)
                hits += r.getheader("X-Cache-Status") == "HIT"
        computed = [metric(admin[p], "effectd_response_cache_misses_total") for p in ports]
        check(all(s == 200 for s in statuses), f"A: {n} distinct signed URLs x {1 + m} through nginx all answered",
              sorted(set(statuses)))
        check(sum(computed) == n and hits == n * m,
              f"A: each distinct answer computed once over the replicas ({computed} = {sum(computed):.0f}), "
              f"the {n * m} repeats served by nginx's cache ({hits} hits)", (computed, hits))
        check(sum(c > 0 for c in computed) >= 2, "A: the hash spreads distinct answers over the replicas", computed)

        # B. One key's quota over the replicas, shared in Redis.
        seconds, results, lock = 5.0, [], threading.Lock()
        counter = iter(range(1000, 10**6))
        start = time.time()

        def client():
            c = http.client.HTTPConnection("127.0.0.1", lb, timeout=30)
            while time.time() - start < seconds:
                with lock:
                    i = next(counter)
                c.request("POST", "/v1/fog", body=json.dumps(fog(i)),
                          headers={"Content-Type": "application/json", "Authorization": "Bearer " + SECRET})
                r = c.getresponse()
                r.read()
                with lock:
                    results.append((time.time(), r.status))

        threads = [threading.Thread(target=client) for _ in range(4)]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        allowed = sum(s == 200 for _, s in results)
        limited = sum(s == 429 for _, s in results)
        span = max(t for t, _ in results) - start
        expected = BURST + PER_MINUTE / 60.0 * span
        per_replica = [metric(admin[p], 'effectd_key_requests_total{key="load",outcome="allowed"}') for p in ports]
        print(f"     B: {len(results)} requests in {span:.2f} s: {allowed} allowed, {limited} limited; quota over "
              f"the span {expected:.1f}; allowed per replica {per_replica}")
        check(abs(allowed - expected) <= 0.1 * expected,
              f"B: admissions {allowed} within 10 % of the key's quota {expected:.1f} over the replicas", allowed)
        check(sum(per_replica) == allowed and sum(x > 0 for x in per_replica) >= 2,
              "B: the replicas' own counts add up to it, from more than one replica", per_replica)
        check(allowed + limited == len(results), "B: every other answer a 429", sorted(set(s for _, s in results)))

        # E. The public path, and health with twice --max-connections trickling clients.
        for path in ("/readyz", "/metrics", "/", "/index.html"):
            conn = http.client.HTTPConnection("127.0.0.1", lb, timeout=10)
            check(get(conn, path).status == 404, f"E: {path} is not served through nginx")
        conn = http.client.HTTPConnection("127.0.0.1", admin[ports[0]], timeout=10)
        check(get(conn, "/metrics").status == 200, "E: a replica's admin port serves /metrics")
        status, ready = readiness(admin[ports[0]])
        check(status == 200 and ready["status"] == "ready" and ready["components"].get("jobStore") == "ready"
              and ready["components"].get("quotaStore") == "ready",
              "E: /readyz names the job store and the quota store, both ready", ready)
        conn = http.client.HTTPConnection("127.0.0.1", ports[0], timeout=10)
        check(get(conn, "/metrics").status == 404, "E: a replica's public port does not")
        slow = []
        for _ in range(2 * MAX_CONNECTIONS):
            sock = socket.create_connection(("127.0.0.1", lb))
            sock.sendall(b"GET /healthz HTTP/1.1\r\nHost: x\r\n")  # and no more
            slow.append(sock)
        time.sleep(0.3)
        waits, statuses = {"nginx": [], "admin": []}, []
        for _ in range(10):
            for name, port in (("nginx", lb), ("admin", admin[ports[0]])):
                conn = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
                t0 = time.monotonic()
                statuses.append(get(conn, "/healthz").status)
                waits[name].append((time.monotonic() - t0) * 1e3)
        check(statuses == [200] * 20, f"E: /healthz through nginx and on the admin port with {len(slow)} trickling clients",
              statuses)
        for sock in slow:
            sock.close()
        print(f"     /healthz with {2 * MAX_CONNECTIONS} clients trickling to nginx: through nginx max "
              f"{max(waits['nginx']):.2f} ms, on the admin port max {max(waits['admin']):.2f} ms")
        check(max(waits["nginx"] + waits["admin"]) < 1000, "E: ... each within a second")

        # F. A job through nginx, with the key.
        keyed = {"Content-Type": "application/json", "Authorization": "Bearer " + BAKER}
        c = http.client.HTTPConnection("127.0.0.1", lb, timeout=60)
        c.request("POST", "/v1/jobs", body=json.dumps({"effect": "lightning", "request": {
            "grid": {"width": 160, "height": 160}, "method": "dbm", "start": [80, 0], "targets": [[80, 159]]}}),
            headers=keyed)
        r = c.getresponse()
        r.read()
        job = r.getheader("Location") or ""
        c.request("GET", job + "/events", headers=keyed)
        events = c.getresponse()
        stream = events.read().decode()
        polls = []
        for _ in range(6):
            c.request("GET", job, headers=keyed)
            reply = c.getresponse()
            polls.append(reply.status)
            state = json.loads(reply.read())
        c.request("GET", job + "/result", headers=keyed)
        result = c.getresponse()
        bolt = json.loads(result.read())
        check(r.status == 202 and "event: done" in stream and polls == [200] * 6 and state["state"] == "done" and
              result.status == 200 and bolt.get("cellCount", 0) > 0,
              "F: a job submitted, followed, polled and fetched through nginx",
              (r.status, stream[-200:], polls, result.status))
        seen = []
        for p in ports:  # each replica, directly: the job is in Redis, not in the one that took it
            d = http.client.HTTPConnection("127.0.0.1", p, timeout=10)
            d.request("GET", job, headers=keyed)
            reply = d.getresponse()
            seen.append((reply.status, json.loads(reply.read()).get("state")))
        check(seen == [(200, "done")] * 3, "F: every replica answers the job's state (done)", seen)
        c.request("POST", "/v1/fog", body=json.dumps(fog(4000)), headers={**keyed, "Prefer": "respond-async"})
        r = c.getresponse()
        r.read()
        check(r.status == 200 and not r.getheader("Preference-Applied"),
              "F: Prefer: respond-async on an effect route through nginx is answered at once", r.status)

        # C. A replica killed (SIGKILL) mid-load: the GETs that reach it afterwards, on nginx's
        # kept-alive connections or new ones, are retried on the next replica; none fails. The
        # kill falls between two of the client's requests: a response the dying replica had
        # begun to send cannot be retried by any proxy (nginx passes a request on only while
        # nothing has gone to the client), which this test does not pretend to cover.
        statuses, kill_now, killed = [], threading.Event(), threading.Event()

        def load():
            c = http.client.HTTPConnection("127.0.0.1", lb, timeout=30)
            for i in range(2000, 2150):
                if i == 2050:
                    kill_now.set()
                    killed.wait(10)
                try:
                    statuses.append(get(c, signed(fog(i))).status)
                except (OSError, http.client.HTTPException) as e:
                    statuses.append(repr(e))
                    c = http.client.HTTPConnection("127.0.0.1", lb, timeout=30)

        t = threading.Thread(target=load)
        t.start()
        kill_now.wait(60)
        procs["effectd1"].send_signal(signal.SIGKILL)
        procs["effectd1"].wait()
        killed.set()
        t.join()
        check(len(statuses) == 150 and all(s == 200 for s in statuses),
              "C: replica 2 SIGKILLed after 50 of 150 GETs: all 150 answered 200", [s for s in statuses if s != 200][:5])

        # G. The replica running a job killed: the job is run again by another and answered.
        c = http.client.HTTPConnection("127.0.0.1", lb, timeout=60)
        c.request("POST", "/v1/jobs", body=json.dumps({"effect": "lightning", "request": {
            "grid": {"width": 256, "height": 256}, "method": "dbm", "start": [128, 0], "targets": [[128, 255]], "seed": 3}}),
            headers=keyed)
        r = c.getresponse()
        r.read()
        job, victim, first = r.getheader("Location") or "", None, None
        deadline = time.monotonic() + 30
        while victim is None and time.monotonic() < deadline:
            c.request("GET", job, headers=keyed)
            state = json.loads(c.getresponse().read())
            if state.get("state") == "running" and state.get("worker"):
                first = state["worker"]
                pid = int(first.split(":")[1])
                victim = next((name for name, p in procs.items() if p.pid == pid), None)
            elif state.get("state") in ("done", "failed", "cancelled"):
                break
            time.sleep(0.02)
        if victim:
            procs[victim].send_signal(signal.SIGKILL)
            procs[victim].wait()
        killed_at = time.monotonic()
        states = []
        while time.monotonic() < killed_at + 60:
            c.request("GET", job, headers=keyed)
            state = json.loads(c.getresponse().read())
            if not states or states[-1] != state["state"]:
                states.append(state["state"])
            if state["state"] in ("done", "failed", "cancelled"):
                break
            time.sleep(0.2)
        c.request("GET", job + "/result", headers=keyed)
        result = c.getresponse()
        bolt = json.loads(result.read())
        check(victim is not None and state["state"] == "done" and state.get("worker") not in (None, first) and
              result.status == 200 and bolt.get("cellCount", 0) > 0,
              f"G: {victim} killed while running the job: {' -> '.join(states)} after "
              f"{time.monotonic() - killed_at:.1f} s, run again by another replica and fetched through nginx",
              (victim, first, state, result.status))

        # H. Redis SIGKILLed and restarted without its data while a job runs: the replica running
        # it registers it again, and its answer is stored and fetched.
        def submit(seed, n=512):
            c.request("POST", "/v1/jobs", body=json.dumps({"effect": "lightning", "request": {
                "grid": {"width": n, "height": n}, "method": "dbm", "start": [n // 2, 0], "targets": [[n // 2, n - 1]],
                "seed": seed}}), headers=keyed)
            r = c.getresponse()
            r.read()
            return r.status, r.getheader("Location") or ""

        def state_of(job):
            c.request("GET", job, headers=keyed)
            r = c.getresponse()
            return r.status, json.loads(r.read())

        def wait_state(job, wanted, seconds):
            seen, deadline = [], time.monotonic() + seconds
            while time.monotonic() < deadline:
                status, state = state_of(job)
                now = state.get("state", status)
                if not seen or seen[-1] != now:
                    seen.append(now)
                if now in wanted:
                    break
                time.sleep(0.1)
            return seen

        status, job = submit(5)
        wait_state(job, ("running",), 30)
        procs["redis"].send_signal(signal.SIGKILL)
        procs["redis"].wait()
        start_redis("redis-empty")  # a new, empty data directory
        seen = wait_state(job, ("done", "failed", "cancelled"), 90)
        c.request("GET", job + "/result", headers=keyed)
        result = c.getresponse()
        bolt = json.loads(result.read())
        registered = sum(metric(admin[p], "effectd_jobs_registered_again_total") for i, p in enumerate(ports)
                         if procs[f"effectd{i}"].poll() is None)
        check(seen[-1] == "done" and result.status == 200 and bolt.get("cellCount", 0) > 0,
              f"H: Redis SIGKILLed and restarted empty while a job ran: {' -> '.join(map(str, seen))}, its answer "
              f"fetched ({registered:.0f} registered again by a heartbeat)", (seen, result.status))
        status, gone = state_of(job[:-4] + ("0000" if job[-4:] != "0000" else "1111"))
        check(status == 404, "H: an id never made is 404", (status, gone))

        # I. Redis restarted from its append-only file: a queued job is still queued, then done.
        status, running = submit(6)
        status, queued = submit(7, 256)
        first = wait_state(queued, ("queued", "running", "done"), 10)
        time.sleep(1.5)  # appendfsync everysec: what is older than a second is on disk
        procs["redis"].send_signal(signal.SIGKILL)
        procs["redis"].wait()
        start_redis("redis-empty")  # the same directory: its AOF is read back
        seen = wait_state(queued, ("done", "failed", "cancelled"), 90)  # 503 while the replicas reconnect
        back = [s for s in seen if s != 503]
        check(first[-1] == "queued" and back[:1] == ["queued"] and back[-1] == "done",
              f"I: Redis SIGKILLed and restarted from its AOF: the queued job {' -> '.join(map(str, seen))}",
              (first, seen))

        # D. Redis stopped: fail open to each replica's own bucket.
        procs["redis"].terminate()
        procs["redis"].wait()
        time.sleep(0.2)
        c = http.client.HTTPConnection("127.0.0.1", lb, timeout=30)
        statuses = []
        for i in range(3000, 3005):
            c.request("POST", "/v1/fog", body=json.dumps(fog(i)),
                      headers={"Content-Type": "application/json", "Authorization": "Bearer " + SECRET})
            r = c.getresponse()
            r.read()
            statuses.append(r.status)
        fallbacks = sum(metric(admin[p], 'effectd_quota_charges_total{store="local-fallback"}')
                        for i, p in enumerate(ports) if procs[f"effectd{i}"].poll() is None)
        check(statuses == [200] * 5 and fallbacks >= 5,
              f"D: Redis stopped: keyed requests answered from per-replica buckets ({fallbacks:.0f} local charges)",
              statuses)
        live = [p for i, p in enumerate(ports) if procs[f"effectd{i}"].poll() is None]
        status, ready = readiness(admin[live[0]])
        check(status == 200 and ready["status"] == "degraded" and
              ready["components"]["jobStore"].startswith("degraded: --jobs-redis unreachable") and
              ready["components"]["quotaStore"].startswith("degraded: --quota-redis unreachable"),
              "D: ... /readyz stays 200, says degraded and names both stores", ready)
        check(metric(admin[live[0]], 'effectd_store_failures_total{store="jobs"}') > 0 and
              metric(admin[live[0]], 'effectd_store_failures_total{store="quota"}') > 0,
              "D: ... and /metrics counts the stores' failed exchanges")
        c.request("GET", job, headers=keyed)
        r = c.getresponse()
        raw = r.read()
        try:
            problem = json.loads(raw)
        except ValueError:  # nginx's own error page: show it rather than a traceback
            problem = {"non-JSON answer": raw[:200].decode(errors="replace")}
        check(r.status == 503 and r.getheader("Retry-After") == "5" and "--jobs-redis" in problem.get("detail", ""),
              "D: ... and a job's status is 503 with Retry-After (the job store is away)", (r.status, problem))
    finally:
        cluster.stop()
        if failures:
            print(cluster.logs())
        shutil.rmtree(work, ignore_errors=True)
    print("deploy_replicas: " + ("passed" if not failures else f"{len(failures)} failed"))
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())
