#!/usr/bin/env python3
"""docs/using/tangents.md, run: its own code (output_mesh, frame, mapped_normal) turns answers into
per-vertex frames, and each frame is checked against the UV derivatives of every triangle that
uses it (dP/du and dP/dv from positions and UVs, computed here):
  - T, B and N are unit and orthogonal, B = w * cross(N, T);
  - T points along +u, and B along +v (bottom-left UV origin) or -v (top-left, and every GLB);
  - w is the triangle's handedness: +1 and -1 both occur on mirrored UVs;
  - a normal-map texel pointing along +x, +y of the texture maps to +dP/du, +-dP/dv.
Meshes: a UV sphere with a seam, the mirrored-UV example, and examples/model.glb (a GLB with
mirrored UVs): its TANGENT, NORMAL, POSITION and TEXCOORD_0 read from the answer.

    python3 tests/using/tangents.py build/server/effectd
"""
import json
import math
import os
import sys

from page import ROOT, Checks, Glb, Server, page_code

page = page_code("tangents")
check = Checks("using_tangents")
server = Server(sys.argv[1])
dot = lambda a, b: sum(x * y for x, y in zip(a, b))  # noqa: E731
sub = lambda a, b: [x - y for x, y in zip(a, b)]      # noqa: E731


def uv_derivatives(p, uv):
    """dP/du and dP/dv of one triangle (seed 004's solve), or None without UV area."""
    e0, e1 = sub(p[1], p[0]), sub(p[2], p[0])
    (u0, v0), (u1, v1) = sub(uv[1], uv[0]), sub(uv[2], uv[0])
    det = u0 * v1 - v0 * u1
    if abs(det) < 1e-9:
        return None
    return [(v1 * a - v0 * b) / det for a, b in zip(e0, e1)], [(u0 * b - u1 * a) / det for a, b in zip(e0, e1)]


def check_frames(name, out, top_left):
    """Every corner's frame against its triangle's UV derivatives."""
    counts = {"corners": 0, "w+": 0, "w-": 0}
    worst_orthogonality, wrong = 0.0, []
    idx = out["indices"]
    for tri in range(0, len(idx), 3):
        ks = idx[tri:tri + 3]
        p = [out["positions"][3 * k:3 * k + 3] for k in ks]
        uv = [out["uvs"][2 * k:2 * k + 2] for k in ks]
        derivatives = uv_derivatives(p, uv)
        if derivatives is None:
            continue
        du, dv = derivatives
        for k in ks:
            t, b, n = page["frame"](out, k)
            w = out["tangents"][4 * k + 3]
            counts["corners"] += 1
            counts["w+" if w > 0 else "w-"] += 1
            worst_orthogonality = max(worst_orthogonality, abs(dot(t, t) - 1), abs(dot(b, b) - 1),
                                      abs(dot(t, n)), abs(dot(b, n)), abs(dot(t, b)))
            along_v = -1 if top_left else 1
            if dot(t, du) <= 0 or along_v * dot(b, dv) <= 0:
                wrong.append((tri // 3, k, t, b, du, dv))
    check(worst_orthogonality < 1e-4, f"{name}: T, B, N unit and orthogonal", worst_orthogonality)
    check(not wrong, f"{name}: T along +u and B along {'-' if top_left else '+'}v at every corner",
          f"{len(wrong)} corners, first {wrong[:1]}")
    return counts


def uv_sphere(rings=10, segments=20):
    positions, uvs, indices = [], [], []
    for i in range(rings + 1):
        theta = math.pi * i / rings
        for j in range(segments + 1):
            phi = 2 * math.pi * j / segments
            positions += [math.sin(theta) * math.cos(phi), math.cos(theta), -math.sin(theta) * math.sin(phi)]
            uvs += [j / segments, 1 - i / rings]  # bottom-left origin: v = 1 at the north pole
    row = segments + 1
    for i in range(rings):
        for j in range(segments):
            a, b, c, d = i * row + j, i * row + j + 1, (i + 1) * row + j, (i + 1) * row + j + 1
            if i > 0:
                indices += [a, c, b]
            if i < rings - 1:
                indices += [b, c, d]
    return {"positions": positions, "uvs": uvs, "indices": indices}


# 1. JSON meshes, both UV origins; normals computed by the service (include normals).
mirrored = json.load(open(os.path.join(ROOT, "proto/examples/tangents/02-mirrored-uvs-split.json")))["mesh"]
for name, mesh in (("UV sphere", uv_sphere()), ("mirrored UVs", mirrored)):
    signs = {}
    for origin in ("bottom-left", "top-left"):
        answer, _ = server.post("/v1/tangents", {"mesh": mesh, "uvOrigin": origin,
                                                 "include": ["tangents", "remap", "indices", "normals"]})
        out = page["output_mesh"](mesh, answer)
        counts = check_frames(f"{name}, {origin}", out, origin == "top-left")
        signs[origin] = out["tangents"][3::4]
        print(f"{name}, {origin}: {answer['vertexCount']} vertices from {len(mesh['positions']) // 3}, {counts}")
    check(all(a == -b for a, b in zip(signs["bottom-left"], signs["top-left"])), f"{name}: top-left negates every w")
    if name == "mirrored UVs":
        check(1 in signs["bottom-left"] and -1 in signs["bottom-left"], "mirrored UVs: both handednesses")

# 2. A normal-map texel through the frame: the flat quad of example 01 (T = +x, B = +y, N = +z).
quad = json.load(open(os.path.join(ROOT, "proto/examples/tangents/01-quad.json")))["mesh"]
answer, _ = server.post("/v1/tangents", dict({"mesh": quad}, include=["tangents", "remap", "indices", "normals"]))
out = page["output_mesh"](quad, answer)
t, b, n = page["frame"](out, 0)
for texel, want in (((0.5, 0.5, 1.0), [0, 0, 1]), ((1.0, 0.5, 0.5), [1, 0, 0]), ((0.5, 1.0, 0.5), [0, 1, 0])):
    got = page["mapped_normal"](t, b, n, texel)
    check(max(abs(g - w) for g, w in zip(got, want)) < 1e-6, f"texel {texel} maps to {want}", got)

# 3. examples/model.glb, the README's example: a GLB with mirrored UVs; glTF's UV origin is top-left.
model = open(os.path.join(ROOT, "examples/model.glb"), "rb").read()
data, headers = server.post("/v1/tangents", model, content_type="model/gltf-binary")
check(headers.get("X-Tangents", "").startswith("generated 1"), "X-Tangents: one primitive got tangents", headers.get("X-Tangents"))
glb = Glb(data)
primitive = glb.doc["meshes"][0]["primitives"][0]
a = primitive["attributes"]
flat = lambda index: [x for v in glb.accessor(index) for x in v]  # noqa: E731
out = {"positions": flat(a["POSITION"]), "normals": flat(a["NORMAL"]), "uvs": flat(a["TEXCOORD_0"]),
       "tangents": flat(a["TANGENT"]), "indices": flat(primitive["indices"])}
source = Glb(model)
before = source.doc["accessors"][source.doc["meshes"][0]["primitives"][0]["attributes"]["POSITION"]]["count"]
counts = check_frames("examples/model.glb", out, top_left=True)
check(counts["w+"] > 0 and counts["w-"] > 0, "examples/model.glb: both handednesses", counts)
print(f"examples/model.glb: {len(out['positions']) // 3} vertices from {before}, {counts}")

server.close()
check.finish()
