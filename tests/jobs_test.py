#!/usr/bin/env python3
"""Jobs from outside (docs/api.md, "Jobs"): effectd started as a binary and called over HTTP as a
baking tool would call it. Each probe asserts what must hold and prints what it measured.

    tests/jobs_test.py build/server/effectd

  same       a job's answer is the synchronous endpoint's: bytes and ETag (response cache off, so
             both were computed), through POST /v1/jobs and through Prefer: respond-async
  limits     a bolt over the synchronous limit (413 naming --max-solver-grid-cells) runs as a job;
             its events: progress with a fraction that never falls, then "done"; the answer has
             the bolt; a job over the job limit is refused when submitted, naming /request/grid
  cancel     DELETE on a running bolt: cancelled within the request, its reservation returned;
             its result 409; a finished job deleted is gone (410; an id never made: 404)
  problems   an unknown effect, an invalid request (its pointer under /request), a wrong method,
             a request over --job-store-mb
  keys       a key's jobs at once are bounded (429), another key cannot see them (404), the
             submission is charged (RateLimit falls by the estimate's units)
  stop       SIGTERM with a job running: the process exits within seconds, not at the job's end
  bake       `effectd bake` writes the endpoint's answer, with plain progress lines, a bar on a
             terminal (a pty), and Ctrl-C cancels its job on the server (exit 130)
"""
import hashlib
import http.client
import json
import os
import pty
import re
import subprocess
import signal
import sys
import tempfile
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import effectd_process  # noqa: E402

failures = []


def check(ok, what, seen=None):
    print(("ok    " if ok else "FAIL  ") + what + ("" if ok or seen is None else f": {seen}"), flush=True)
    if not ok:
        failures.append(what)


def request(port, method, path, body=None, headers=None, timeout=60):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    h = {"Content-Type": "application/json", **(headers or {})} if body is not None else dict(headers or {})
    c.request(method, path, body=body, headers=h)
    r = c.getresponse()
    data = r.read()
    c.close()
    return r.status, {k: v for k, v in r.getheaders()}, data


def bolt(n, **more):
    """A DBM bolt on an n x n grid to its grounded bottom row (the hero shot's layout)."""
    return {"grid": {"width": n, "height": n}, "method": "dbm", "neighbourhood": 4, "start": [n // 2, 0],
            "targetRegion": {"rows": [{"y": n - 1, "runs": [[0, n]]}]}, **more}


def wait_done(port, location, headers=None, seconds=120):
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        _, _, body = request(port, "GET", location, headers=headers)
        state = json.loads(body)
        if state["state"] in ("done", "failed", "cancelled"):
            return state
        time.sleep(0.05)
    return state


def events(port, location, headers=None, timeout=120):
    """The job's Server-Sent Events until the stream ends: [(event, data)]."""
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=timeout)
    c.request("GET", location + "/events", headers=headers or {})
    r = c.getresponse()
    check(r.status == 200 and r.getheader("Content-Type", "").startswith("text/event-stream"),
          "/events is a text/event-stream", (r.status, r.getheader("Content-Type")))
    out, event = [], None
    for raw in r:
        line = raw.decode().rstrip("\n")
        if line.startswith("event: "):
            event = line[7:]
        elif line.startswith("data: "):
            out.append((event, json.loads(line[6:])))
    c.close()
    return out


def same(binary):
    p, port = effectd_process.start(binary, "--access-log", "0", "--response-cache-mb", "0")
    try:
        for name, route, body in [("lightning", "/v1/lightning", bolt(96, include=["polylines"])),
                                  ("fog", "/v1/fog", {"fog": {"fogType": "GL_EXP2", "density": 0.07}, "table": {"size": 64}})]:
            text = json.dumps(body)
            s_status, s_headers, s_body = request(port, "POST", route, text)
            for how in ("POST /v1/jobs", "Prefer: respond-async"):
                if how == "POST /v1/jobs":
                    status, headers, answer = request(port, "POST", "/v1/jobs",
                                                      json.dumps({"effect": name, "request": body}))
                else:
                    status, headers, answer = request(port, "POST", route, text, {"Prefer": "respond-async"})
                location = headers.get("Location", "")
                check(status == 202 and re.fullmatch(r"/v1/jobs/[0-9a-f]+", location) and
                      headers.get("Preference-Applied") == "respond-async" and json.loads(answer)["effect"] == name,
                      f"{name} by {how}: 202, Location, Preference-Applied", (status, headers))
                state = wait_done(port, location)
                j_status, j_headers, j_body = request(port, "GET", location + "/result")
                check(state["state"] == "done" and j_status == s_status == 200 and j_body == s_body and
                      j_headers.get("ETag") == s_headers.get("ETag") and j_headers.get("ETag"),
                      f"{name} by {how}: the answer's bytes and ETag are the endpoint's "
                      f"({len(j_body)} bytes, {j_headers.get('ETag')})",
                      (state["state"], j_status, s_status, j_headers.get("ETag"), s_headers.get("ETag")))
                status, _, _ = request(port, "GET", location + "/result", headers={"If-None-Match": s_headers["ETag"]})
                check(status == 304, f"{name} by {how}: If-None-Match on the result gives 304", status)
                status, headers, coded = request(port, "GET", location + "/result", headers={"Accept-Encoding": "br, gzip"})
                check(status == 200 and coded == s_body and "Content-Encoding" not in headers,
                      f"{name} by {how}: the result goes as stored whatever the client accepts (its ETag names those bytes)",
                      headers.get("Content-Encoding"))
    finally:
        p.terminate()
        p.wait()


def limits_cancel_problems(binary):
    p, port = effectd_process.start(binary, "--access-log", "0", "--max-solver-grid-cells", "16384",
                                    "--max-job-grid-cells", "262144", "--job-store-mb", "1")
    try:
        big = bolt(300)
        status, _, body = request(port, "POST", "/v1/lightning", json.dumps(big))
        check(status == 413 and b"--max-solver-grid-cells" in body and
              b"send it as a job: POST /v1/jobs or Prefer: respond-async (jobs take up to 262144 cells" in body,
              "300^2 dbm over the synchronous limit: 413 naming the limit and saying to send it as a job", body[:400])
        status, _, body = request(port, "POST", "/v1/lightning", json.dumps(bolt(600)))
        check(status == 413 and b"send it as a job" not in body,
              "600^2 dbm over the job limit too: 413 without the job hint", body[:400])
        status, headers, _ = request(port, "POST", "/v1/jobs", json.dumps({"effect": "lightning", "request": big}))
        location = headers.get("Location", "")
        t0 = time.monotonic()
        seen = events(port, location)
        seconds = time.monotonic() - t0
        fractions = [d["progress"]["fraction"] for e, d in seen if e == "progress"]
        print(f"      300^2 dbm job: {len(seen)} events over {seconds:.1f} s, fractions "
              f"{[round(f, 2) for f in fractions[::max(1, len(fractions) // 8)]]}, last {seen[-1][0] if seen else None}")
        check(status == 202 and len(fractions) >= 3 and fractions == sorted(fractions) and seen[-1][0] == "done" and
              seen[-1][1]["progress"]["fraction"] == 1 and any(0 < f < 1 for f in fractions),
              "... runs as a job: progress events with a fraction that never falls, then done", seen[-3:])
        status, headers, body = request(port, "GET", location + "/result")
        answer = json.loads(body) if status == 200 else {}
        check(status == 200 and answer.get("grid") == [300, 300] and answer.get("method", "").startswith("dbm") and
              answer.get("struck", [0, 0])[1] == 299, "... its answer is the bolt, struck on the bottom row",
              (status, {k: answer.get(k) for k in ("grid", "method", "struck")}))
        status, _, body = request(port, "POST", "/v1/jobs", json.dumps({"effect": "lightning", "request": bolt(600)}))
        problem = json.loads(body)
        check(status == 413 and problem["errors"] and problem["errors"][0]["pointer"].startswith("/request/grid") and
              "--max-job-grid-cells" in json.dumps(problem) and "--max-solver-grid-cells" not in json.dumps(problem) and
              "send it as a job" not in json.dumps(problem),
              "a job over --max-job-grid-cells: 413 when submitted, at /request/grid, naming that flag",
              (status, problem.get("detail"), problem.get("errors")))

        # Cancel: a bolt that takes several seconds, stopped while it grows.
        status, headers, _ = request(port, "POST", "/v1/jobs", json.dumps({"effect": "lightning", "request": bolt(400)}))
        location = headers["Location"]
        for _ in range(200):
            state = json.loads(request(port, "GET", location)[2])
            if state["state"] == "running" and state["progress"]["steps"] > 0:
                break
            time.sleep(0.05)
        t0 = time.monotonic()
        status, _, body = request(port, "DELETE", location)
        ms = (time.monotonic() - t0) * 1e3
        state = json.loads(body)
        _, _, metrics = request(port, "GET", "/metrics")
        reserved = re.search(rb"^effectd_memory_reserved_bytes (\S+)$", metrics, re.M)
        print(f"      DELETE on a running 400^2 job after {state['progress']['steps']} steps: {status} in {ms:.0f} ms")
        check(status == 200 and state["state"] == "cancelled" and reserved and float(reserved.group(1)) == 0,
              "DELETE stops a running job within the request, its memory reservation returned",
              (status, state["state"], reserved and reserved.group(1)))
        check(ms < 1000, f"... in under a second ({ms:.0f} ms; a bolt reports every 50 ms)")
        status, _, body = request(port, "GET", location + "/result")
        check(status == 409 and json.loads(body)["type"].endswith("/cancelled"), "a cancelled job's result: 409", status)
        # A finished job deleted: forgotten.
        status, headers, _ = request(port, "POST", "/v1/jobs",
                                     json.dumps({"effect": "fog", "request": {"fog": {"fogType": "GL_LINEAR"}}}))
        done = wait_done(port, headers["Location"])
        d_status, _, _ = request(port, "DELETE", headers["Location"])
        g_status, _, g_body = request(port, "GET", headers["Location"])
        off = headers["Location"][:-1] + ("0" if headers["Location"][-1] != "0" else "1")  # an id never made
        check(request(port, "GET", off)[0] == 404, "an id one digit off a job's (never made): 404")
        check(done["state"] == "done" and d_status == 204 and g_status == 410 and b"no longer here" in g_body,
              "a finished job deleted is gone: 410 saying why, not 404",
              (done["state"], d_status, g_status))

        # Problems.
        status, _, body = request(port, "POST", "/v1/jobs", json.dumps({"effect": "thunder", "request": {}}))
        check(status == 400 and b"/effect" in body, "an unknown effect: 400 naming /effect", status)
        status, _, body = request(port, "POST", "/v1/jobs", json.dumps({"effect": "fog", "request": {"fog": {"density": -1}}}))
        problem = json.loads(body)
        check(status == 400 and all(e["pointer"].startswith("/request/fog") for e in problem["errors"]),
              "an invalid request: 400 with its fields under /request", problem.get("errors"))
        status, headers, _ = request(port, "GET", "/v1/jobs")
        check(status == 405 and "POST" in headers.get("Allow", ""), "GET /v1/jobs: 405, Allow: POST", status)
        # Queued requests count against --job-store-mb: a 1.7 MB mesh does not fit in 1 MiB.
        n = 60000
        mesh = {"mesh": {"positions": [0.5] * (3 * n), "uvs": [0.25] * (2 * n), "indices": list(range(n))}}
        status, _, body = request(port, "POST", "/v1/jobs", json.dumps({"effect": "tangents", "request": mesh}))
        check(status == 503 and b"--job-store-mb" in body, "a request larger than --job-store-mb: 503 naming it", status)
        status, _, _ = request(port, "GET", "/v1/jobs/0123456789abcdef")
        check(status == 404, "an unknown job: 404", status)

    finally:
        p.terminate()
        p.wait()


def keys(binary):
    work = tempfile.mkdtemp(prefix="effectd-jobs.")
    secrets = {"a": "job-secret-a", "b": "job-secret-b"}
    with open(os.path.join(work, "keys.json"), "w") as f:
        json.dump({"keys": [{"id": k, "sha256": hashlib.sha256(s.encode()).hexdigest(), "perMinute": 6000,
                             "burst": 6000} for k, s in secrets.items()]}, f)
    p, port = effectd_process.start(binary, "--access-log", "0", "--api-keys", os.path.join(work, "keys.json"),
                                    "--key-max-jobs", "1", "--max-job-grid-cells", "262144")
    auth = {k: {"Authorization": "Bearer " + s} for k, s in secrets.items()}
    try:
        status, _, _ = request(port, "POST", "/v1/jobs", json.dumps({"effect": "lightning", "request": bolt(64)}))
        check(status == 401, "without a key: 401", status)
        body = json.dumps({"effect": "lightning", "request": bolt(300)})
        status, headers, _ = request(port, "POST", "/v1/jobs", body, auth["a"])
        left = float(headers.get("RateLimit", ";r=6000;").split(";r=")[1].split(";")[0])
        location = headers.get("Location", "")
        print(f"      key a submits a 300^2 dbm job: {status}, {6000 - left:g} units charged")
        check(status == 202 and left < 6000 - 1, "a job is charged to its key when submitted", headers.get("RateLimit"))
        status, _, body2 = request(port, "POST", "/v1/jobs", json.dumps({"effect": "fog", "request": {"fog": {}}}),
                                   auth["a"])
        check(status == 429 and b"too-many-jobs" in body2, "a key's second job at once past --key-max-jobs 1: 429", status)
        status, _, _ = request(port, "GET", location, headers=auth["b"])
        check(status == 404, "another key cannot see the job (404)", status)
        status, _, _ = request(port, "GET", location, headers=auth["a"])
        check(status == 200, "its own key sees it", status)
        request(port, "DELETE", location, headers=auth["a"])
    finally:
        p.terminate()
        p.wait()


def stop(binary):
    p, port = effectd_process.start(binary, "--access-log", "0", "--max-job-grid-cells", "262144")
    status, headers, _ = request(port, "POST", "/v1/jobs", json.dumps({"effect": "lightning", "request": bolt(480)}))
    time.sleep(1)
    t0 = time.monotonic()
    p.send_signal(signal.SIGTERM)
    try:
        code = p.wait(30)
    except Exception:
        p.kill()
        code = None
    seconds = time.monotonic() - t0
    print(f"      SIGTERM with a 480^2 job running: exit {code} after {seconds:.2f} s")
    # The job alone would take 20 s (minutes under ASan); it stops at its next progress report,
    # after the step being solved (up to seconds under ASan).
    check(status == 202 and code == 0 and seconds < 10, "SIGTERM with a job running: the process exits at once (0)",
          (status, code, seconds))


def bake(binary):
    p, port = effectd_process.start(binary, "--access-log", "0", "--max-job-grid-cells", "262144")
    work = tempfile.mkdtemp(prefix="effectd-bake.")
    try:
        body = bolt(300, include=["polylines"])
        path, out = os.path.join(work, "bolt.json"), os.path.join(work, "bolt-answer.json")
        with open(path, "w") as f:
            json.dump(body, f)
        server = f"http://127.0.0.1:{port}"
        r = subprocess.run([binary, "bake", "lightning", path, "-o", out, "--server", server], capture_output=True,
                           text=True, timeout=120)
        lines = r.stderr.strip().split("\n")
        progress = [line for line in lines if re.match(r"^ *\d+%  ", line)]
        print(f"      bake, not a terminal: exit {r.returncode}, {len(progress)} progress lines, last: {lines[-1]}")
        status, _, direct = request(port, "POST", "/v1/lightning", json.dumps(body))
        with open(out, "rb") as f:
            baked = f.read()
        check(r.returncode == 0 and baked == direct and status == 200, "effectd bake writes the endpoint's answer",
              (r.returncode, r.stderr[-300:]))
        check(progress and progress[-1].startswith("100%  done") and "\r" not in r.stderr,
              "... with plain progress lines off a terminal, the last 100% done", progress[-2:])
        # On a terminal (a pty): the bar, redrawn in place.
        leader, follower = pty.openpty()
        q = subprocess.Popen([binary, "bake", "lightning", path, "-o", out, "--server", server], stderr=follower,
                             stdout=subprocess.DEVNULL)
        os.close(follower)
        seen = b""
        while True:
            try:
                chunk = os.read(leader, 4096)
            except OSError:
                break
            if not chunk:
                break
            seen += chunk
        q.wait(60)
        check(q.returncode == 0 and b"\r\x1b[K[" in seen and b"#" in seen and b"100%" in seen,
              "... and a bar redrawn in place on a terminal", seen[-200:])
        # Ctrl-C: the job is cancelled on the server.
        with open(path, "w") as f:
            json.dump(bolt(480), f)
        q = subprocess.Popen([binary, "bake", "lightning", path, "-o", out, "--server", server],
                             stderr=subprocess.PIPE, text=True)
        time.sleep(1.5)
        q.send_signal(signal.SIGINT)
        _, err = q.communicate(timeout=30)
        _, _, metrics = request(port, "GET", "/metrics")
        check(q.returncode == 130 and b'effectd_jobs{state="cancelled"} 1' in metrics and "cancelled" in err,
              "Ctrl-C in effectd bake cancels its job on the server (exit 130)", (q.returncode, err[-200:]))
    finally:
        p.terminate()
        p.wait()


if __name__ == "__main__":
    binary = sys.argv[1]
    for probe in (same, limits_cancel_problems, keys, stop, bake):
        print(f"-- {probe.__name__}", flush=True)
        probe(binary)
    print(f"{len(failures)} failed" if failures else "all passed")
    sys.exit(1 if failures else 0)
