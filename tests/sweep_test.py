#!/usr/bin/env python3
"""Property sweep: requests drawn at random from the full ranges the request schemas allow,
checked against invariants (not snapshots).

Each request is an example of its endpoint (proto/examples/<e>/*.json) with one to three
numeric, integer, boolean, enum or short numeric-array properties set to values drawn
log-uniformly over their magnitudes or taken from the exact edges (minimum, maximum, 0, -0,
the smallest positive double, one ulp inside each bound). Invariants:
  - no 5xx, no hang (a request over --timeout seconds);
  - every 4xx is a problem naming at least one field;
  - every 2xx JSON answer has no NaN or Infinity and is valid against its answer schema
    (proto/schemas/<e>-answer.json, checked by python3-jsonschema: fog factors in [0, 1],
    intensities, thin-film colours ...);
  - fog: a 1-D table's factors never rise with distance;
  - lightning: every cell inside the grid, each one a neighbour of its parent, none twice;
  - tangents: unit tangents orthogonal to their normals, handedness +-1;
  - bubble meshes: no triangle inverted against the undisturbed sphere, no degenerate one.
A failing case is minimised (its mutations dropped one at a time while it still fails) and
printed; add it to tests/sweep_regressions.json, which every run replays first.

    tests/sweep_test.py build/server/effectd [--requests N] [--seed S] [--timeout S] [--json OUT]
"""
import argparse
import copy
import http.client
import json
import math
import os
import random
import sys
import time
import warnings

import jsonschema

from effectd_process import start
from schema_walk import ROOT, SCHEMAS, examples, properties, resolve, with_value

ENDPOINTS = ["fog", "lightning", "bubble", "tangents", "scene"]  # not render: its PNG/GIF bytes are 8-bit
# Properties the sweep leaves alone, and why.
SKIP = {
    "lightning": {"/maxSteps": "budget: 1e9 steps on the largest grid is minutes by design (capped by --max-growth-steps)",
                  "/tolerance": "dbm at 1e-12 on large grids is seconds per step by design"},
}
REGRESSIONS = os.path.join(ROOT, "tests", "sweep_regressions.json")


def number_values(prop, rng):
    """A value for a number/integer property: an edge or a log-uniform magnitude in range."""
    integer = prop.get("type") == "integer"
    lo = prop.get("minimum", prop.get("exclusiveMinimum"))
    hi = prop.get("maximum", prop.get("exclusiveMaximum"))
    if lo is not None and "exclusiveMinimum" in prop and "minimum" not in prop:
        lo = lo + 1 if integer else math.nextafter(lo, math.inf)
    if hi is not None and "exclusiveMaximum" in prop and "maximum" not in prop:
        hi = hi - 1 if integer else math.nextafter(hi, -math.inf)
    lo = -1e300 if lo is None else lo
    hi = 1e300 if hi is None else hi
    inside = lambda v: lo <= v <= hi
    if rng.random() < 0.4:  # an edge
        if integer:
            edges = [lo, hi, lo + 1, hi - 1, 0, 1]
        else:
            edges = [lo, hi, math.nextafter(lo, math.inf), math.nextafter(hi, -math.inf), 0.0, -0.0, 5e-324, 1.0]
        edges = [v for v in edges if inside(v)]
        return int(rng.choice(edges)) if integer else rng.choice(edges)
    # Log-uniform magnitude between the smallest interesting and the largest allowed.
    big = max(abs(lo), abs(hi), 1e-12)
    sign = rng.choice([-1, 1]) if lo < 0 < hi else (1 if lo >= 0 else -1)
    for _ in range(20):
        v = sign * 10 ** rng.uniform(-12, math.log10(big))
        if integer:
            v = int(round(v))
        if inside(v):
            return v
    return int(lo) if integer else lo


def value_for(prop, rng):
    """A random valid value for a property the sweep varies, or None for one it does not."""
    if "enum" in prop:
        return rng.choice(prop["enum"])
    t = prop.get("type")
    if t in ("number", "integer"):
        return number_values(prop, rng)
    if t == "boolean":
        return rng.choice([True, False])
    if t == "array":
        items, _ = resolve(prop.get("items", {}), "common.json")
        n = prop.get("minItems", 0)
        if n and n == prop.get("maxItems") and n <= 4 and items.get("type") in ("number", "integer"):
            return [number_values(items, rng) for _ in range(n)]
    return None


def variable_properties(endpoint):
    name = endpoint + ".json"
    out = []
    for pointer, prop, _ in properties(SCHEMAS[name], name):
        if pointer in SKIP.get(endpoint, {}) or pointer == "/include":
            continue
        if value_for(prop, random.Random(0)) is not None:
            out.append((pointer, prop))
    return out


class Server:
    def __init__(self, binary, timeout):
        self.binary, self.timeout = binary, timeout
        self.p, self.port = start(binary, "--access-log", "0", "--response-cache-mb", "0")
        self.conn = None

    def post(self, path, body):
        """(status, answer: dict | bytes | None on a timeout, seconds)."""
        t0 = time.monotonic()
        for attempt in range(2):  # a kept-alive connection the server closed: once more, afresh
            try:
                if self.conn is None:
                    self.conn = http.client.HTTPConnection("127.0.0.1", self.port, timeout=self.timeout)
                self.conn.request("POST", path, body=json.dumps(body), headers={"Content-Type": "application/json"})
                r = self.conn.getresponse()
                data = r.read()
                break
            except TimeoutError:
                self.conn = None
                return 0, None, time.monotonic() - t0
            except (OSError, http.client.HTTPException):
                self.conn = None
                if attempt == 1:
                    return 0, None, time.monotonic() - t0
        seconds = time.monotonic() - t0
        if r.getheader("Content-Type", "").endswith("json"):
            def constant(name):
                raise ValueError(f"{name} in the answer")
            try:
                return r.status, json.loads(data, parse_constant=constant), seconds
            except ValueError as e:
                return r.status, {"__invalid__": str(e)}, seconds
        return r.status, data, seconds

    def stop(self):
        self.p.terminate()
        self.p.wait()


def answer_validator(endpoint):
    schema = SCHEMAS[endpoint + "-answer.json"]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        resolver = jsonschema.RefResolver(base_uri="", referrer=schema, store=dict(SCHEMAS))
        return jsonschema.Draft202012Validator(schema, resolver=resolver)


# ---- invariants ------------------------------------------------------------------------------
def check_lightning(body, answer, server):
    problems = []
    w, h = answer["grid"]
    cells = answer.get("cells")
    if cells is None:
        return problems
    xy = list(zip(cells[0::2], cells[1::2]))
    if any(not (0 <= x < w and 0 <= y < h) for x, y in xy):
        problems.append("a cell outside the grid")
    if len(set(xy)) != len(xy):
        problems.append("a cell twice")
    parent = answer.get("tree", {}).get("parent")
    if parent:
        hood = body.get("neighbourhood", 8)
        for i, q in enumerate(parent[1:], 1):
            dx, dy = abs(xy[i][0] - xy[q][0]), abs(xy[i][1] - xy[q][1])
            if max(dx, dy) != 1 or (hood == 4 and dx + dy != 1):
                problems.append(f"cell {i} is not a neighbour of its parent")
                break
    return problems


def check_tangents(body, answer, server):
    problems = []
    t, n = answer.get("tangents"), answer.get("normals")
    if not t or not n:
        return problems
    for i in range(len(t) // 4):
        tx, ty, tz, tw = t[4 * i:4 * i + 4]
        nx, ny, nz = n[3 * i:3 * i + 3]
        length = math.sqrt(tx * tx + ty * ty + tz * tz)
        if abs(length - 1) > 1e-3 or abs(tx * nx + ty * ny + tz * nz) > 1e-3 or abs(abs(tw) - 1) > 0:
            problems.append(f"vertex {i}: tangent |t| {length:.4f}, t.n {tx * nx + ty * ny + tz * nz:.2e}, w {tw}")
            break
    return problems


def check_bubble(body, answer, server):
    """Each triangle against the same triangle of the undisturbed sphere (the same request with
    no wobble): the same orientation and a nonzero area."""
    mesh = answer.get("mesh") or {}
    pos, idx = mesh.get("positions"), mesh.get("indices")
    if not pos or not idx:
        return []
    still = with_value(body, "/params/wobbleAmplitude", 0)
    status, plain, _ = server.post("/v1/bubble", still)
    if status != 200 or plain["mesh"]["indices"] != idx:
        return [f"the undisturbed sphere of the same request: {status}"]
    ref = plain["mesh"]["positions"]

    def cross(p, tri):
        a, b, c = ([p[3 * v + k] for k in range(3)] for v in tri)
        u = [b[k] - a[k] for k in range(3)]
        v = [c[k] - a[k] for k in range(3)]
        return [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]], u, v

    for t in range(0, len(idx), 3):
        n, u, v = cross(pos, idx[t:t + 3])
        n0, _, _ = cross(ref, idx[t:t + 3])
        scale = max(1e-300, sum(x * x for x in u) + sum(x * x for x in v))
        if math.sqrt(sum(x * x for x in n)) <= 1e-9 * scale:
            return [f"triangle {t // 3} is degenerate"]
        if sum(n[k] * n0[k] for k in range(3)) < 0:
            return [f"triangle {t // 3} is inverted"]
    return []


def check_fog(body, answer, server):
    """A 1-D table's factors never rise with distance: fog only accumulates along a ray, up to
    the cutoff distance (beyond it f = 1); and never fall below 1 - maxOpacity."""
    table = answer.get("table") or {}
    f = table.get("factor")
    if not f or table.get("elevations"):
        return []
    floor = 1 - ((body.get("fog") or {}).get("maxOpacity", 1) if isinstance(body.get("fog"), dict) else 1)
    start, end = table["range"]
    cutoff = table.get("cutoffDistance", float("inf"))
    for i in range(len(f)):
        if f[i] < floor - 1e-6:
            return [f"table factor {f[i]} at entry {i} is below 1 - maxOpacity = {floor}"]
    for i in range(1, len(f)):
        if start + (end - start) * i / (len(f) - 1) > cutoff:
            break
        if f[i] > f[i - 1] + 1e-6:
            return [f"table factor rises with distance at entry {i}: {f[i - 1]} -> {f[i]}"]
    return []


CHECKS = {"lightning": check_lightning, "tangents": check_tangents, "bubble": check_bubble, "fog": check_fog}


def truncated(v, keep=2000):
    """v with every array cut to its first `keep` items: python's validator takes seconds on
    answers of millions of numbers (level-7 meshes, 4096^2 bolts); NaN and Infinity were
    already refused while parsing the whole answer."""
    if isinstance(v, dict):
        return {k: truncated(x, keep) for k, x in v.items()}
    if isinstance(v, list):
        return [truncated(x, keep) for x in v[:keep]]
    return v


def violations(server, endpoint, body, status, answer, seconds, validators):
    if answer is None:
        return [f"no answer within the timeout ({seconds:.0f} s)"]
    if status >= 500:
        return [f"{status}: {answer.get('detail') if isinstance(answer, dict) else answer[:200]}"]
    if not isinstance(answer, dict):
        return []  # binary answers (GLB) are checked by tests/mikktspace/gltf.mjs
    if "__invalid__" in answer:
        return [answer["__invalid__"]]
    if 400 <= status < 500:
        return [] if answer.get("errors") else [f"{status} names no field: {answer.get('detail')}"]
    found = [f"answer schema: {e.message[:200]} at {'/'.join(map(str, e.absolute_path))}"
             for e in list(validators[endpoint].iter_errors(truncated(answer)))[:2]]
    return found + CHECKS.get(endpoint, lambda b, a, s: [])(body, answer, server)


def include_everything(endpoint, body):
    """The example asking for the answer parts the invariants look at."""
    wanted = {"lightning": ["polylines", "cells", "tree"]}.get(endpoint)
    if wanted:
        body["include"] = wanted
    return body


def minimise(server, endpoint, base, mutations, validators):
    """The fewest of `mutations` (pointer, value) that still break an invariant."""
    def fails(ms):
        body = base
        for pointer, value in ms:
            body = with_value(body, pointer, value)
        status, answer, seconds = server.post("/v1/" + endpoint, body)
        if answer is None:  # a trial that hung: the next one gets a fresh server
            server.stop()
            server.__init__(server.binary, server.timeout)
            return True
        return bool(violations(server, endpoint, body, status, answer, seconds, validators))
    kept = list(mutations)
    for m in list(kept):
        trial = [x for x in kept if x != m]
        if trial and fails(trial):
            kept = trial
    return kept


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--requests", type=int, default=400)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--timeout", type=float, default=60)
    ap.add_argument("--json")
    args = ap.parse_args()
    rng = random.Random(args.seed)
    validators = {e: answer_validator(e) for e in ENDPOINTS}
    variable = {e: variable_properties(e) for e in ENDPOINTS}
    bases = {e: [include_everything(e, b) for b in examples(e)] for e in ENDPOINTS}
    server = Server(args.binary, args.timeout)
    counts = {"requests": 0, "invariantsChecked": 0, "violations": 0, "byStatus": {}, "byEndpoint": {},
              "slowest": [0, ""], "regressions": 0}
    failures = []

    def run(endpoint, body, mutations, base):
        status, answer, seconds = server.post("/v1/" + endpoint, body)
        counts["requests"] += 1
        counts["byStatus"][str(status)] = counts["byStatus"].get(str(status), 0) + 1
        counts["byEndpoint"][endpoint] = counts["byEndpoint"].get(endpoint, 0) + 1
        counts["invariantsChecked"] += 1 + (status == 200) * (2 + (endpoint in CHECKS))
        if seconds > counts["slowest"][0]:
            counts["slowest"] = [round(seconds, 2), f"{endpoint} {json.dumps(mutations)[:200]}"]
        found = violations(server, endpoint, body, status, answer, seconds, validators)
        if found:
            counts["violations"] += 1
            if answer is None:  # the server may still be busy with it: minimise on a fresh one
                server.stop()
                server.__init__(args.binary, args.timeout)
            kept = minimise(server, endpoint, base, mutations, validators) if mutations else []
            for pointer, value in kept:
                base = with_value(base, pointer, value)
            failures.append({"endpoint": endpoint, "violations": found, "mutations": kept,
                             "body": base if mutations else body})
            if answer is None:  # the server may still be busy with it: start afresh
                server.stop()
                server.__init__(args.binary, args.timeout)

    try:
        for case in json.load(open(REGRESSIONS)) if os.path.exists(REGRESSIONS) else []:
            counts["regressions"] += 1
            run(case["endpoint"], case["body"], [], case["body"])
        deadline = time.monotonic() + 10 * args.requests  # a bound even if every request is slow
        while counts["requests"] - counts["regressions"] < args.requests and time.monotonic() < deadline:
            endpoint = rng.choice(ENDPOINTS)
            base = rng.choice(bases[endpoint])
            mutations = []
            body = base
            for pointer, prop in rng.sample(variable[endpoint], k=min(len(variable[endpoint]), rng.choice([1, 1, 2, 3]))):
                value = value_for(prop, rng)
                new = with_value(body, pointer, value)
                if new is not None:
                    body = new
                    mutations.append([pointer, value])
            run(endpoint, body, mutations, base)
    finally:
        server.stop()
    print(json.dumps({k: v for k, v in counts.items()}, sort_keys=True))
    for f in failures:
        print("VIOLATION", json.dumps(f)[:2000])
    if args.json:
        with open(args.json, "w") as out:
            json.dump({"counts": counts, "failures": failures, "seed": args.seed}, out, indent=1)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
