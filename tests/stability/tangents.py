"""Tangents' stiff and extreme cases: MikkTSpace's frames (docs/effects.md §4) written out here and
checked at every corner, on degenerate and mirrored meshes, zero normals and coordinates from
1e-30 to 1e38. Each row's mutation flips a frame (t → −t: still unit and ⟂ n)."""
import json
import math
import os

from stability.common import ROOT, Mutation, case, frozen, ok_status, statuses, worst
from sweep_test import check_tangents

QUAD = frozen({"positions": (0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0), "uvs": (0, 0, 1, 0, 1, 1, 0, 1),
               "indices": (0, 1, 2, 0, 2, 3)})
FRAMES = ("tangents", "normals", "indices", "remap")
FLT_MIN = 1.1754943508222875e-38


def scaled(mesh, k):
    return {**mesh, "positions": [v * k for v in mesh["positions"]]}


def frame_problems(body, a):
    """MikkTSpace's frame, written out (docs/effects.md §4): at every corner of a triangle with no two
    coincident corners and a UV area above FLT_MIN, the tangent points along ∂p/∂u projected into
    the normal's plane (positive dot product) and w = sign(UV area); a vertex no such triangle
    reaches (and no such triangle's corner at the same position) has the fallback frame: (1, 0, 0)
    projected into the normal's plane, w = −1."""
    mesh = body["mesh"]
    pos, uvs = mesh["positions"], mesh["uvs"]
    t, n = a.get("tangents"), a.get("normals")
    if not t or not n:
        return ["the answer has no tangents or no normals"]
    nv, nin = len(t) // 4, len(pos) // 3
    remap = a.get("remap") or (list(range(nin)) if nv == nin else None)
    idx = a.get("indices") or (mesh["indices"] if nv == nin else None)
    if remap is None or idx is None:
        return ["split vertices with no remap or indices to check them by"]
    P = [tuple(pos[3 * remap[k]:3 * remap[k] + 3]) for k in range(nv)]
    U = [tuple(uvs[2 * remap[k]:2 * remap[k] + 2]) for k in range(nv)]
    healthy, healthy_at = set(), set()
    for c in range(0, len(idx), 3):
        tri = idx[c:c + 3]
        p0, p1, p2 = (P[k] for k in tri)
        if p0 == p1 or p1 == p2 or p0 == p2:
            continue
        d1, d2 = [b - a for a, b in zip(p0, p1)], [b - a for a, b in zip(p0, p2)]
        t21, t31 = [b - a for a, b in zip(U[tri[0]], U[tri[1]])], [b - a for a, b in zip(U[tri[0]], U[tri[2]])]
        area = t21[0] * t31[1] - t21[1] * t31[0]
        os_ = [t31[1] * x - t21[1] * y for x, y in zip(d1, d2)]  # = area·∂p/∂u (the reference's eq 18)
        if abs(area) <= FLT_MIN or not any(os_):
            continue
        sign = 1.0 if area > 0 else -1.0
        for k in tri:
            nk = n[3 * k:3 * k + 3]
            dot_n = sum(x * y for x, y in zip(nk, os_))
            proj = [sign * (x - dot_n * y) for x, y in zip(os_, nk)]
            if math.hypot(*proj) <= 1e-6 * math.hypot(*os_):
                continue
            healthy.add(k)
            healthy_at.add(P[k])
            tk = t[4 * k:4 * k + 4]
            if sum(x * y for x, y in zip(tk, proj)) <= 0:
                return [f"vertex {k}: the tangent points against ∂p/∂u"]
            if tk[3] != sign:
                return [f"vertex {k}: w = {tk[3]:g}, the UV area's sign is {sign:g}"]
    for k in range(nv):
        nk = n[3 * k:3 * k + 3]
        if k in healthy or P[k] in healthy_at or abs(nk[0]) > 0.9:
            continue
        e = [1 - nk[0] * nk[0], -nk[0] * nk[1], -nk[0] * nk[2]]
        le = math.hypot(*e)
        if max(abs(x - y / le) for x, y in zip(t[4 * k:4 * k + 3], e)) > 1e-5 or t[4 * k + 3] != -1:
            return [f"vertex {k}: {t[4 * k:4 * k + 4]}, not the fallback frame"]
    return []


def _flip_frame(answers, server):
    """The first frame flipped: t → −t (still unit and ⟂ n), in the last answer."""
    t = answers[-1][1]["tangents"]
    t[0:3] = [-x for x in t[0:3]]


FLIPPED = Mutation("the first frame flipped (t → −t: still unit, ⟂ n)", _flip_frame)
FLIPPED_AT_LARGEST = Mutation("the first frame flipped at the largest scale", _flip_frame)


def tangents_equal_at_scales(body, scales):
    """The same tangents at every scale as at scale 1 (mutation: FLIPPED_AT_LARGEST)."""
    def check(answers, server):
        if not ok_status(200, answers):
            return False, statuses(answers)
        ref = answers[0][1]["tangents"]
        err = max(worst(a["tangents"], ref) for _, a in answers[1:])
        probs = [p for (_, a), k in zip(answers, [1] + scales) for p in check_tangents({}, a, None) +
                 frame_problems({"mesh": scaled(body["mesh"], k)}, a)]
        return err <= 1e-6 and not probs, (f"max |t(scale) − t(1)| {err:.2g} at scales {', '.join(f'{k:g}' for k in scales)}"
                                           + ("; " + probs[0] if probs else "; MikkTSpace's frames at every scale"))
    return check


def unit_frames(body, pred=None):
    """check_tangents (unit, ⟂ n, w = ±1) and frame_problems (the direction and handedness); then
    pred(answer). Mutation: FLIPPED."""
    def check(answers, server):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        probs = check_tangents({}, a, None) + frame_problems(body, a)
        seen = f"{len(a['tangents']) // 4} unit tangents ⟂ normals, along ∂p/∂u or the fallback" if not probs else probs[0]
        if pred:
            ok2, s2 = pred(a)
            return not probs and ok2, seen + "; " + s2
        return not probs, seen
    return check


def bad_triangles(body):
    """(triangles with two coincident corners, the others with UV area 0), counted here."""
    m = body["mesh"]
    p, uv, idx = m["positions"], m["uvs"], m["indices"]
    coincident = zero_uv = 0
    for c in range(0, len(idx), 3):
        tri = idx[c:c + 3]
        pts = [tuple(p[3 * v:3 * v + 3]) for v in tri]
        if len(set(pts)) < 3:
            coincident += 1
            continue
        (u0, v0), (u1, v1), (u2, v2) = (uv[2 * v:2 * v + 2] for v in tri)
        zero_uv += (u1 - u0) * (v2 - v0) - (v1 - v0) * (u2 - u0) == 0
    return coincident, zero_uv


def cases(quick):
    examples = os.path.join(ROOT, "proto/examples/tangents")
    with open(os.path.join(examples, "04-degenerate-triangles.json")) as f:
        degenerate = {**json.load(f), "include": list(FRAMES) + ["stats"]}
    with open(os.path.join(examples, "02-mirrored-uvs-split.json")) as f:
        mirrored = json.load(f)
    coincident = {"mesh": {"positions": [0, 0, 0, 0, 0, 0, 1, 1, 0], "uvs": [0, 0, 1, 0, 1, 1], "indices": [0, 1, 2]},
                  "include": list(FRAMES)}
    sliver = {"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1e-16, 0], "uvs": [0, 0, 1, 0, 0, 1, 1, 0.5],
                       "indices": [0, 1, 2, 1, 3, 2]}, "include": list(FRAMES)}
    zero_normals = {"mesh": {**QUAD, "normals": [0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1]}, "include": list(FRAMES) + ["stats"]}
    zero_at = [v for v in range(4) if not any(zero_normals["mesh"]["normals"][3 * v:3 * v + 3])]
    bad = bad_triangles(degenerate)
    return [
        case("tangents", "zero-area triangles and zero-area UVs", "tangents", degenerate,
             check=unit_frames(degenerate, lambda a: (
                 [a["stats"]["counters"].get(k) for k in ("degenerateTriangles", "zeroUvAreaTriangles")] == list(bad),
                 f"{a['stats']['counters'].get('degenerateTriangles', 0):g} triangles with coincident corners and "
                 f"{a['stats']['counters'].get('zeroUvAreaTriangles', 0):g} of zero UV area counted")),
             must="unit frames ⟂ normals everywhere, the fallback frame where no triangle gives one; the counters equal "
             f"the script's count: {bad[0]} triangles with coincident corners, {bad[1]} with zero UV area",
             mutation=FLIPPED),
        case("tangents", "mirrored UVs", "tangents", mirrored,
             check=unit_frames(mirrored, lambda a: ({-1.0, 1.0} <= set(a["tangents"][3::4]),
                                                    f"handedness {sorted(set(a['tangents'][3::4]))}")),
             must="both handednesses present: each corner's w the sign of its triangle's UV area, its tangent along ∂p/∂u",
             mutation=FLIPPED),
        case("tangents", "coincident corners", "tangents", coincident, check=unit_frames(coincident),
             must="no area: the fallback frame ((1, 0, 0) in the normal's plane, w = −1), unit and finite", mutation=FLIPPED),
        case("tangents", "a triangle of area 1e-16 beside a healthy one", "tangents", sliver, check=unit_frames(sliver),
             must="the sliver's frame is unit, finite, orthogonal to its normal and along its ∂p/∂u", mutation=FLIPPED),
        case("tangents", "zero-length given normals", "tangents", zero_normals,
             check=unit_frames(zero_normals, lambda a: (
                 a["stats"]["counters"].get("replacedNormals") == len(zero_at)
                 and all(a["normals"][3 * v:3 * v + 3] == [0, 0, 1] for v in zero_at),
                 f"replacedNormals {a['stats']['counters'].get('replacedNormals')}, normals "
                 + ", ".join(str(a["normals"][3 * v:3 * v + 3]) for v in zero_at))),
             must=f"the {len(zero_at)} zero normals (vertices {', '.join(map(str, zero_at))}) replaced by +z and counted; "
             "frames along ∂p/∂u", mutation=FLIPPED),
        case("tangents", "coordinates at 1e-30, 1e6 and 1e38 scale", "tangents",
             [{"mesh": scaled(QUAD, k), "include": list(FRAMES)} for k in (1, 1e-30, 1e6, 1e38)],
             check=tangents_equal_at_scales({"mesh": dict(QUAD)}, [1e-30, 1e6, 1e38]),
             must="tangents are directions: the same as at scale 1 within 1e-6, along ∂p/∂u at every scale",
             mutation=FLIPPED_AT_LARGEST),
    ]
