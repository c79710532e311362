"""What the tests of docs/using/*.md share: the page's own code, a server, and checks.

Each page holds its steps as one Python block between the markers
    <!-- using-test:begin -->  and  <!-- using-test:end -->
and its test runs exactly that block (exec), so the page and the test cannot drift apart: change
the page's code and the test runs the change. The test then checks the result against something
the page's code did not compute (the server's own per-point answers, the request's geometry,
closed forms).
"""
import http.client
import json
import os
import re
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.dirname(HERE))  # tests/: effectd_process
from effectd_process import start  # noqa: E402

BLOCK = re.compile(r"<!-- using-test:begin -->\s*```python\n(.*?)```\s*<!-- using-test:end -->", re.S)


def page_code(name):
    """The Python blocks of docs/using/<name>.md, run in order in one fresh namespace that is
    returned (a later block may use an earlier one's functions, as the page's reader does)."""
    path = os.path.join(ROOT, "docs", "using", f"{name}.md")
    blocks = BLOCK.findall(open(path, encoding="utf-8").read())
    if not blocks:
        raise SystemExit(f"{path}: no python block between the using-test markers")
    namespace = {"__name__": f"docs/using/{name}.md"}
    for block in blocks:
        exec(compile(block, path, "exec"), namespace)
    return namespace


class Server:
    """effectd on a free port, spoken to over one kept-alive connection."""

    def __init__(self, binary):
        self.process, self.port = start(binary, "--access-log", "0")
        self.connection = http.client.HTTPConnection("127.0.0.1", self.port, timeout=60)

    def post(self, path, body, content_type="application/json"):
        data = body if isinstance(body, bytes) else json.dumps(body).encode()
        self.connection.request("POST", path, body=data, headers={"Content-Type": content_type})
        r = self.connection.getresponse()
        payload = r.read()
        if r.status != 200:
            raise SystemExit(f"POST {path}: {r.status} {payload[:400]!r}")
        if (r.getheader("Content-Type") or "").startswith("application/json"):
            return json.loads(payload), dict(r.getheaders())
        return payload, dict(r.getheaders())

    def close(self):
        self.connection.close()
        self.process.terminate()
        self.process.wait(10)


class Glb:
    """A binary glTF read with the standard library: its JSON (`doc`) and accessors as lists."""
    COMPONENTS = {5120: "b", 5121: "B", 5122: "h", 5123: "H", 5125: "I", 5126: "f"}
    SIZES = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4, "MAT4": 16}

    def __init__(self, data):
        import struct
        magic, version, length = struct.unpack_from("<4sII", data, 0)
        if magic != b"glTF" or version != 2 or length != len(data):
            raise ValueError("not a glTF 2.0 binary")
        json_length, _ = struct.unpack_from("<I4s", data, 12)
        self.doc = json.loads(data[20:20 + json_length])
        at = 20 + json_length
        self.bin = b""
        if at < len(data):
            bin_length, _ = struct.unpack_from("<I4s", data, at)
            self.bin = data[at + 8:at + 8 + bin_length]

    def accessor(self, index):
        """Accessor `index` as a list of tuples (one per element; scalars as 1-tuples)."""
        import struct
        a = self.doc["accessors"][index]
        view = self.doc["bufferViews"][a["bufferView"]]
        code, n = self.COMPONENTS[a["componentType"]], self.SIZES[a["type"]]
        size = struct.calcsize(code)
        stride = view.get("byteStride", size * n)
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        return [struct.unpack_from(f"<{n}{code}", self.bin, start + k * stride) for k in range(a["count"])]


class Checks:
    """Counts checks; collects failures with their detail; exits 1 if any failed."""

    def __init__(self, name):
        self.name, self.count, self.failures, self.started = name, 0, [], time.monotonic()

    def __call__(self, ok, what, detail=""):
        self.count += 1
        if not ok:
            self.failures.append(f"{what}: {detail}")
            print(f"FAIL {what}: {detail}", flush=True)
        return ok

    def finish(self):
        took = time.monotonic() - self.started
        if self.failures:
            print(f"{self.name}: {len(self.failures)} of {self.count} checks failed ({took:.1f} s)")
            sys.exit(1)
        print(f"{self.name}: {self.count} checks passed ({took:.1f} s)")
