#!/usr/bin/env python3
"""The contract's defaults and ranges are the server's: for every property of every request
schema (proto/schemas/*.json) that has one,
  - "default": the answer without the property equals the answer with it set to the default
    (so the handler's and the library's defaults are the schema's), and so does the memory the
    server reserves for it (X-Memory-Reserved, the two bodies padded to one length: the cost
    model reads the same parsed request);
  - "minimum"/"maximum" (and exclusive bounds nudged inside), every "enum" value: a request
    with that value is not refused with 400 naming that field (so validate() is no stricter
    than the schema; 413 and 422 remain possible: server limits, impossible combinations).
Each property is tried on the first example request of its endpoint (proto/examples/<e>/01-*)
asking for everything the endpoint can answer ("include": every value), its parent objects
created when absent. Exceptions, each with its reason, are in ALLOWED.

    tests/schema_truth_test.py build/server/effectd
"""
import glob, http.client, json, os, sys, time

from answers import scrub
from effectd_process import start
from schema_walk import ROOT, SCHEMAS as schemas, properties, resolve, with_value

BIN = sys.argv[1]
ENDPOINTS = {"fog.json": "/v1/fog", "lightning.json": "/v1/lightning", "bubble.json": "/v1/bubble",
             "tangents.json": "/v1/tangents", "scene.json": "/v1/scene"}
# Include values left out of the "everything" request, and why.
NOT_INCLUDED = {
    "fog.json": ["samples"],       # needs a "samples" object the example does not have
    "lightning.json": ["error"],   # runs the converged Laplace reference: seconds per request
}
# Members an include needs that the first example does not have, added to it.
SEEDS = {
    "fog.json": {"glow": {"camera": [0, 1, 0], "source": [0, 40, -60]}},  # the glow's ray through the fog
}
# (schema, pointer, check) -> why the rule does not hold there.
ALLOWED = {
    **{(schema, pointer, f"enum {n}"):
       "6 and 26 are the 3-D neighbourhoods: the example's grid is 2-D (no grid.depth), where 4 and 8 apply"
       for schema, pointer in (("lightning.json", "/neighbourhood"), ("scene.json", "/lightning/neighbourhood"))
       for n in (6, 26)},
    **{("fog.json", "/fog/convention", f'enum "{engine}"'):
       "an engine's convention is its height fog: the example's fog is X3D LINEAR, refused at /fog/convention "
       "(tests/fog_engines/conventions_test.py tries every convention on HEIGHT fogs)"
       for engine in ("filament", "unreal")},
    ("bubble.json", "/thinFilm/thicknessRange", "default"):
        "the thin-film table's default is [0, 1000] nm as stated; the glTF extension block keeps "
        "KHR_materials_iridescence's own 100-400 nm unless a range is given (api_bubble.cpp)",
}

failures, checked = [], {"default": 0, "range": 0, "enum": 0}


class Server:
    def __init__(self):
        self.p, self.port = start(BIN, "--access-log", "0", "--response-cache-mb", "0")

    def post(self, path, body, length=0):
        """(status, answer, X-Memory-Reserved); the body padded with spaces to `length` bytes."""
        start = time.monotonic()
        try:
            return self._post(path, body, length)
        finally:
            if time.monotonic() - start > 2:
                print(f"slow: {time.monotonic() - start:.1f} s {path} {json.dumps(body)[:300]}", flush=True)

    def _post(self, path, body, length):
        c = http.client.HTTPConnection("127.0.0.1", self.port, timeout=120)
        text = json.dumps(body)
        c.request("POST", path, body=text + " " * (length - len(text)), headers={"Content-Type": "application/json"})
        r = c.getresponse()
        data = r.read()
        c.close()
        return r.status, (json.loads(data) if data[:1] in (b"{", b"[") else data), r.getheader("X-Memory-Reserved")


def names_field(answer, pointer):
    if not isinstance(answer, dict):
        return False
    return any(e.get("pointer") == pointer for e in answer.get("errors", []))


def check(schema, pointer, kind, ok, detail):
    if (schema, pointer, kind) in ALLOWED:
        return
    if not ok:
        failures.append(f"{schema} {pointer} {kind}: {detail}")


def main():
    server = Server()
    try:
        for name, path in ENDPOINTS.items():
            if len(sys.argv) > 2 and name not in sys.argv[2:]:
                continue
            example = sorted(glob.glob(os.path.join(ROOT, "proto/examples", path.split("/")[-1], "01-*.json")))[0]
            base = json.load(open(example))
            base.update(SEEDS.get(name, {}))
            # Everything the endpoint can answer, so that every default can show in the answer.
            include, _ = resolve(schemas[name].get("properties", {}).get("include", {}), name)
            items, _ = resolve(include.get("items", {}), name)
            if "enum" in items:
                base["include"] = [v for v in items["enum"] if v not in NOT_INCLUDED.get(name, [])]
            status, _, _ = server.post(path, base)
            if status != 200:
                failures.append(f"{example}: {status}")
                continue
            for pointer, prop, parent in properties(schemas[name], name):
                if "default" in prop:
                    without = with_value(base, pointer, None, remove=True)
                    given = with_value(base, pointer, prop["default"])
                    if without is not None:
                        length = max(len(json.dumps(without)), len(json.dumps(given)))
                        a, b = server.post(path, without, length), server.post(path, given, length)
                        checked["default"] += 1
                        check(name, pointer, "default", a[0] == b[0] and scrub(a[1]) == scrub(b[1]),
                              f"absent -> {a[0]}, default {json.dumps(prop['default'])} -> {b[0]}; answers differ")
                        check(name, pointer, "default (cost)", a[2] == b[2],
                              f"absent -> X-Memory-Reserved {a[2]}, default {json.dumps(prop['default'])} -> {b[2]}")
                values = []
                if prop.get("type") in ("number", "integer"):
                    lo, hi = prop.get("minimum"), prop.get("maximum")
                    if lo is None and "exclusiveMinimum" in prop:
                        lo = prop["exclusiveMinimum"] + (1 if prop["type"] == "integer" else 1e-9 * max(1, abs(prop["exclusiveMinimum"])))
                    if hi is None and "exclusiveMaximum" in prop:
                        hi = prop["exclusiveMaximum"] - (1 if prop["type"] == "integer" else 1e-9 * max(1, abs(prop["exclusiveMaximum"])))
                    values += [("range", v) for v in (lo, hi) if v is not None]
                values += [("enum", v) for v in prop.get("enum", [])]
                for kind, v in values:
                    body = with_value(base, pointer, v)
                    if body is None:
                        continue
                    checked[kind] += 1
                    status, answer, _ = server.post(path, body)
                    check(name, pointer, f"{kind} {json.dumps(v)}", not (status == 400 and names_field(answer, pointer)),
                          f"{status} {answer.get('detail') if isinstance(answer, dict) else ''}")
    finally:
        server.p.terminate()
        server.p.wait()
    print(f"checked {checked['default']} defaults, {checked['range']} bounds, {checked['enum']} enum values")
    for f in failures:
        print("FAIL " + f)
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
