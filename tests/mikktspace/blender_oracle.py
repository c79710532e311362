#!/usr/bin/env python3
"""/v1/tangents against a second MikkTSpace: Blender's own (Mesh.calc_tangents, Debian's
`blender`, run headless by blender_tangents.py). Meshes: a UV sphere whose pole triangles have an
area of ~1e-16 (its pole vertices lie sin(pi) apart), a torus, mirrored UV islands, and Debian's
assimp-testmodels spider. Each corner's tangent from the service (tangents[indices[c]]) is
compared with Blender's for that corner: >= 99.9 % within 0.1 degrees with the same sign. The service is given Blender's own vertex
normals (blender_tangents.py says why). Exits 77 (ctest: skipped), saying why, where blender
cannot run.

    tests/mikktspace/blender_oracle.py build/server/effectd
"""
import http.client
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, ".."))
from effectd_process import start  # noqa: E402

SPIDER = "/usr/share/assimp/models/OBJ/spider.obj"


def uv_sphere(rings, segments):
    """Both triangles of every band: at the poles one joins two pole vertices ~1e-16 apart."""
    p, n, uv, idx = [], [], [], []
    for r in range(rings + 1):
        th = math.pi * r / rings
        for s in range(segments + 1):
            ph = 2 * math.pi * s / segments
            x, y, z = math.sin(th) * math.cos(ph), math.cos(th), math.sin(th) * math.sin(ph)
            p += [x, y, z]
            n += [x, y, z]
            uv += [s / segments, 1 - r / rings]
    row = segments + 1
    for r in range(rings):
        for s in range(segments):
            a = r * row + s
            b = a + row
            idx += [a, a + 1, b, a + 1, b + 1, b]
    return {"name": "uv sphere with 1e-16-area pole triangles", "positions": p, "normals": n, "uvs": uv, "indices": idx}


def torus(big, small, nu, nv):
    p, n, uv, idx = [], [], [], []
    for i in range(nu + 1):
        u = 2 * math.pi * i / nu
        for j in range(nv + 1):
            v = 2 * math.pi * j / nv
            cx, cz = math.cos(u), math.sin(u)
            p += [(big + small * math.cos(v)) * cx, small * math.sin(v), (big + small * math.cos(v)) * cz]
            n += [math.cos(v) * cx, math.sin(v), math.cos(v) * cz]
            uv += [i / nu * 3, j / nv]
    row = nv + 1
    for i in range(nu):
        for j in range(nv):
            a = i * row + j
            b = a + row
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return {"name": "torus", "positions": p, "normals": n, "uvs": uv, "indices": idx}


def mirrored(nx, ny):
    p, uv, idx = [], [], []
    for j in range(ny + 1):
        for i in range(nx + 1):
            x, y = 2 * i / nx - 1, j / ny
            p += [x, y, 0.2 * math.sin(3 * x) * math.cos(2 * y)]
            uv += [abs(x), y]
    row = nx + 1
    for j in range(ny):
        for i in range(nx):
            a = j * row + i
            idx += [a, a + 1, a + row, a + 1, a + row + 1, a + row]
    return {"name": "mirrored UV islands", "positions": p, "uvs": uv, "indices": idx}


def obj(path):
    """Every distinct v/vt/vn triple a vertex; polygons fanned."""
    v, vt, vn, p, n, uv, idx, seen = [], [], [], [], [], [], [], {}
    for line in open(path):
        f = line.split()
        if not f:
            continue
        if f[0] == "v":
            v.append([float(x) for x in f[1:4]])
        elif f[0] == "vt":
            vt.append([float(x) for x in f[1:3]])
        elif f[0] == "vn":
            vn.append([float(x) for x in f[1:4]])
        elif f[0] == "f":
            corners = []
            for c in f[1:]:
                if c not in seen:
                    parts = (c.split("/") + ["", ""])[:3]
                    seen[c] = len(p) // 3
                    p += v[int(parts[0]) - 1]
                    uv += vt[int(parts[1]) - 1] if parts[1] else [0, 0]
                    n += vn[int(parts[2]) - 1] if parts[2] else [0, 0, 1]
                corners.append(seen[c])
            for k in range(1, len(corners) - 1):
                idx += [corners[0], corners[k], corners[k + 1]]
    return {"name": os.path.basename(path), "positions": p, "normals": n, "uvs": uv, "indices": idx}


def main():
    binary = sys.argv[1]
    blender = shutil.which("blender")
    if not blender:
        print("skip: blender is not installed (scripts/setup.sh installs Debian's blender)")
        sys.exit(77)
    meshes = [uv_sphere(24, 48), torus(1, 0.35, 48, 24), mirrored(40, 20)]
    if os.path.exists(SPIDER):
        meshes.append(obj(SPIDER))
    # Blender first: its normals and tangents.
    with tempfile.TemporaryDirectory() as tmp:
        given = [{"name": m["name"], "positions": m["positions"], "indices": m["indices"],
                  "uvs": [m["uvs"][2 * v + k] for v in m["indices"] for k in (0, 1)]} for m in meshes]
        inp, out = os.path.join(tmp, "in.json"), os.path.join(tmp, "out.json")
        json.dump(given, open(inp, "w"))
        run = subprocess.run([blender, "-b", "--factory-startup", "--python", os.path.join(HERE, "blender_tangents.py"),
                              "--", inp, out], capture_output=True, text=True, timeout=600)
        if run.returncode != 0 or not os.path.exists(out):
            print(f"skip: blender could not run headless here (exit {run.returncode}): {run.stderr[-600:]}")
            sys.exit(77)
        ref = json.load(open(out))
    # Then the service, with Blender's vertex normals.
    proc, port = start(binary, "--access-log", "0")
    try:
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=120)
        answers = []
        for m, b in zip(meshes, ref):
            body = {"mesh": {"positions": m["positions"], "normals": b["normals"], "uvs": m["uvs"], "indices": m["indices"]},
                    "include": ["tangents", "indices", "normals"]}
            conn.request("POST", "/v1/tangents", body=json.dumps(body), headers={"Content-Type": "application/json"})
            r = conn.getresponse()
            data = r.read()
            if r.status != 200:
                sys.exit(f"{m['name']}: HTTP {r.status} {data[:300]!r}")
            answers.append(json.loads(data))
    finally:
        proc.terminate()
        proc.wait()
    failed = False
    for m, a, b in zip(meshes, answers, ref):
        corners = len(m["indices"])
        if b["loops"] != corners or b["corners"] != m["indices"]:
            print(f"FAIL {m['name']}: Blender's corners are not the mesh's ({b['loops']} of {corners})")
            failed = True
            continue
        ok = worst = flips = placeholders = 0
        for c in range(corners):
            o = a["indices"][c]
            t = a["tangents"][4 * o:4 * o + 4]
            r = b["tangents"][4 * c:4 * c + 4]
            lr = math.sqrt(sum(x * x for x in r[:3]))
            # No frame (no UV-valid triangle at the vertex): the service writes MikkTSpace's
            # placeholder (1, 0, 0), w = -1, projected into the normal's plane, and Blender's C++
            # port writes its own there: where they differ, counted apart.
            nv = a["normals"][3 * o:3 * o + 3]
            x = [1 - nv[0] * nv[0], -nv[0] * nv[1], -nv[0] * nv[2]]
            lx = math.sqrt(sum(v * v for v in x))
            placeholder = t[3] == -1 and lx > 1e-3 and sum(abs(t[k] - x[k] / lx) for k in range(3)) < 1e-4
            cos = sum(t[k] * r[k] for k in range(3)) / lr if lr > 0 else -1
            deg = math.degrees(math.acos(max(-1.0, min(1.0, cos))))
            if placeholder and (deg > 0.1 or t[3] != r[3]):
                placeholders += 1
                continue
            worst = max(worst, deg)
            flips += t[3] != r[3]
            ok += deg <= 0.1 and t[3] == r[3]
        defined = corners - placeholders
        share = ok / defined if defined else 1
        good = share >= 0.999
        failed |= not good
        print(f"{'ok  ' if good else 'FAIL'} {m['name']}: {corners} corners, {100 * share:.3f} % of {defined} within 0.1 deg "
              f"and the same sign, max {worst:.4f} deg, {flips} sign differences; {placeholders} placeholders where Blender writes its own")
    sys.exit(1 if failed else 0)


if __name__ == "__main__":
    main()
