#!/usr/bin/env python3
"""The stability report as checks: every effect's stiff and extreme cases sent to a running
effectd, each with a check that can fail (a closed form computed here, an invariance between
requests, or the exact 4xx it must get), and docs/stability.md written from what they saw.
A row is "right" only when its check passes; --check exits 1 when one does not.

    scripts/stability-report.py build/server/effectd [--quick] [--check] [--no-sweep] [--mutations]
                                [--sweep-requests N] [--out docs/stability.md]

--quick runs the smaller sizes of the heavy cases (the test suite runs it with --check and
--mutations); the report (scripts/report.sh) runs the full sizes and the property sweep.
--mutations shows that every check can fail: each row also has a mutation, a plausible wrong
answer made from the real ones (a fog factor 1 % off or the naive overflow's 1, a bolt cell moved
off its tree, a mesh vertex nudged, a tangent frame flipped, a 4xx naming another field, a linear
table's entries under a warped table's axes, a preview's bubble 20 % brighter or moved 3 pixels, ...),
fed to the same check, which must reject it ("caught"); with --check a mutation that is NOT
caught fails the run like a failed row.
"""
import argparse
import copy
import datetime
import json
import math
import os
import struct
import subprocess
import sys
import tempfile
import time
import zlib

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "tests"))
from sweep_test import Server, check_bubble, check_tangents  # noqa: E402
from report_stamp import stamp  # noqa: E402  (scripts/report_stamp.py)

QUAD = {"positions": [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0], "uvs": [0, 0, 1, 0, 1, 1, 0, 1], "indices": [0, 1, 2, 0, 2, 3]}


# ---- closed forms (docs/effects.md section 2), computed here, not read from the server ---------
def height_f(a, b, h, oy, dy, t, near_level=0.0):
    """exp(-tau), tau = a e^(-b(oy-h)) t g(b dy t), g(x) = (1 - e^-x)/x, in log space: a·t, b·dy·t
    and g never formed as products that could overflow (a = 1e300 with t = 1e300, t = 1e200).
    near_level > 0 is Filament's guard (docs/effects.md §2.4 F2): g = 1 where |b dy t| <= it."""
    if t == 0 or a == 0:
        return 1.0
    ltau = math.log(a) + math.log(t) - b * (oy - h)
    if b != 0 and dy != 0:
        lx = math.log(b) + math.log(abs(dy)) + math.log(t)  # ln |x|
        if lx > 709 and dy < 0:
            return 0.0  # e^|x| overflows: tau = infinity
        x = math.copysign(math.exp(lx), dy)
        if abs(x) <= near_level:
            pass
        elif abs(x) < 1e-12:
            ltau += -x / 2
        elif x > 0:
            ltau += math.log(-math.expm1(-x)) - lx
        elif x > -700:
            ltau += math.log(math.expm1(-x)) - lx
        else:
            ltau += -x - lx
    return 0.0 if ltau > 709 else math.exp(-math.exp(ltau))


LN2 = math.log(2.0)


def unreal_f(f, camera, point):
    """Unreal's GetExponentialHeightFog in effectd's units (docs/effects.md §2.4, U1-U4), one layer,
    written out here: base 2 per world unit (A = a/ln²2, B = b/ln2); the observer lowered to 65536
    units above the layer (U4), the ray from there to the point (its rise v_y grows by the drop);
    the density at the observer with its exponent clamped to [−125, 126] (U3); F = max(−127, B·v_y)
    (U3); I = A'·(1 − 2^−F)/F, or the Taylor term A'·(ln2 − ln²2·F/2) where |F| ≤ 0.01 (U2);
    f = saturate(2^(−I·L)), L = |observer → point|. Components from half-differences (no overflow
    at ±1e200); a product that overflows is ∞ and 2^−∞ = 0."""
    a, b, h = f.get("density", 1), f.get("heightFalloff", 0.1), f.get("baseHeight", 0)
    if a == 0:
        return 1.0
    A, B = a / (LN2 * LN2), b / LN2
    observer = min(camera[1], h + 65536.0)
    half = [0.5 * q - 0.5 * p for p, q in zip(camera, point)]
    vy = 2 * half[1] + (camera[1] - observer)
    length = math.hypot(2 * half[0], vy, 2 * half[2])
    terms = A * 2.0 ** min(max(-B * (observer - h), -125.0), 126.0)
    F = max(-127.0, B * vy)
    line = terms * -math.expm1(-F * LN2) / F if abs(F) > 0.01 else terms * (LN2 - 0.5 * LN2 * LN2 * F)
    return min(1.0, max(0.0, 2.0 ** -(line * length)))


def exp_neg(*factors):
    """e^(-product of factors), the product taken as a sum of logs: 1e300·1e-300, (1e-200·1e200)²
    or 5e-324·(1e162)² never overflow or underflow on the way."""
    if any(x == 0 for x in factors):
        return 1.0
    lp = sum(math.log(x) for x in factors)
    return 0.0 if lp > 709 else math.exp(-math.exp(lp))


def one_minus_exp_neg(*factors):
    """1 - e^(-product), as -expm1 (exact for products of 1e-298)."""
    if any(x == 0 for x in factors):
        return 0.0
    lp = sum(math.log(x) for x in factors)
    return 1.0 if lp > 709 else -math.expm1(-math.exp(lp))


def ray(frm, to):
    """(length, unit direction) from frm to to: half the difference (no overflow for coordinates of
    ±1e300) and math.hypot (no square formed: 1e-300 and 1e200 come out as themselves)."""
    half = [0.5 * q - 0.5 * p for p, q in zip(frm, to)]
    h = math.hypot(*half)
    return (0.0, (0.0, 0.0, 0.0)) if h == 0 else (2 * h, tuple(x / h for x in half))


def fog_model(f, camera, point):
    """(f, transmittance, fog colour) of docs/effects.md §2 for an object at point seen from camera:
    the closed forms written out here, not the server's code. Transmittance and fog colour are
    those `samples` carry for ATMOSPHERIC or with `directional` (colour = object·T + fog colour)."""
    if any(k in f for k in ("startDistance", "maxOpacity", "cutoffDistance", "secondLayer")):
        raise ValueError("fog_model has no engine terms")
    d, u = ray(camera, point)
    color = f.get("color", [1, 1, 1])
    t, conv = f.get("fogType", "LINEAR"), f.get("convention", "effectd")
    if t in ("LINEAR", "EXPONENTIAL"):
        v = f.get("visibilityRange", 0)
        factor = 1.0 if v == 0 else 0.0 if d >= v else (v - d) / v if t == "LINEAR" else math.exp(-(d / (v - d)))
    elif t == "GL_LINEAR":
        s, e = f.get("start", 0), f.get("end", 1)
        factor = min(1.0, max(0.0, (e - d) / (e - s)))
    elif t == "GL_EXP":
        factor = exp_neg(f.get("density", 1), d)
    elif t == "GL_EXP2":
        factor = exp_neg(f.get("density", 1), d, f.get("density", 1), d)
    elif t in ("DISTANCE_EXP2", "DISTANCE_GAUSSIAN"):
        factor = exp_neg(f.get("distanceCoefficient", 0.07), d, d)
        factor *= f.get("peak", 1 / math.sqrt(2 * math.pi)) if t == "DISTANCE_GAUSSIAN" else 1
    elif t == "HEIGHT" and conv == "effectd":
        factor = height_f(f.get("density", 1), f.get("heightFalloff", 0.1), f.get("baseHeight", 0), camera[1], u[1], d)
    elif t == "HEIGHT" and conv == "filament":  # m·d, m the whole ray's mean density (F2: sigma(c_y) near level)
        factor = height_f(f.get("density", 1), f.get("heightFalloff", 0.1), f.get("baseHeight", 0), camera[1], u[1], d,
                          near_level=0.00125)
    elif t == "HEIGHT" and conv == "unreal":
        factor = unreal_f(f, camera, point)
    elif t == "ATMOSPHERIC":
        tr = [exp_neg(b, d) for b in f.get("extinction", [0, 0, 0])]
        return (sum(tr) / 3, tr, [c * one_minus_exp_neg(b, d) for c, b in zip(color, f.get("inscattering", [0, 0, 0]))])
    else:
        raise ValueError(f"fog_model: {t} in convention {conv}")
    sun = f.get("directional")
    if sun is None:
        return factor, None, None
    if conv != "effectd":
        raise ValueError(f"fog_model: directional in convention {conv}")
    if sun.get("startDistance", 0) != 0:
        raise ValueError("fog_model: directional.startDistance")
    cos = sum(a * b for a, b in zip(u, ray([0, 0, 0], sun.get("direction", [0, 0, -1]))[1])) if d > 0 else 0.0
    g = sun.get("g", 0.7)
    lobe = (max(cos, 0.0) ** sun["exponent"] if "exponent" in sun else (1 - g * g) / (1 + g * g - 2 * g * cos) ** 1.5)
    glow = [c * lobe for c in sun.get("color", [1, 0.8, 0.6])]
    return factor, [factor] * 3, [(1 - factor) * (c + s) for c, s in zip(color, glow)]


def region_of(regions, p):
    """The innermost region holding p (closed sets; the smallest volume, compared as logs so that
    radii of 1e-200 and 1e200 compare; the earlier on ties), -1 for none."""
    best, best_lv = -1, math.inf
    for i, r in enumerate(regions):
        if "sphere" in r:
            inside = ray(r["sphere"]["center"], p)[0] <= r["sphere"]["radius"]
            rad = r["sphere"]["radius"]
            lv = math.log(4 / 3 * math.pi) + 3 * math.log(rad) if rad > 0 else -math.inf
        else:
            lo, hi = r["box"]["min"], r["box"]["max"]
            inside = all(a <= x <= b for a, x, b in zip(lo, p, hi))
            ext = [0.5 * b - 0.5 * a for a, b in zip(lo, hi)]
            lv = sum(math.log(e) + math.log(2) if e > 0 else -math.inf for e in ext)
        if inside and (best < 0 or lv < best_lv):
            best, best_lv = i, lv
    return best


def distances(table):
    start, end = table["range"]
    n = table["size"]
    return [end if i == n - 1 else start + (end - start) * i / (n - 1) for i in range(n)]


def worst(observed, expected):
    return max(abs(o - e) for o, e in zip(observed, expected))


# ---- request builders ---------------------------------------------------------------------------
def fog(f, **extra):
    return {"fog": {"color": [0.7, 0.75, 0.8], **f}, **extra}


def bolt(n, **extra):
    return {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n - 1]],
            "include": ["cells", "tree", "stats"], **extra}


def channel(width, length, seed, **extra):
    return {"grid": {"width": width, "height": length}, "start": [width // 2, 0], "targets": [[width // 2, length - 1]],
            "method": "dbm", "seed": seed, "include": ["stats"], **extra}


def tube(length, seed):
    return {"grid": {"width": 3, "height": 3, "depth": length}, "start": [1, 1, 0], "targets": [[1, 1, length - 1]],
            "method": "dbm", "neighbourhood": 6, "seed": seed, "include": ["stats"]}


def walled(n):
    rects = [[n // 2 - 2, n // 2 - 2, 5, 1], [n // 2 - 2, n // 2 + 2, 5, 1], [n // 2 - 2, n // 2 - 2, 1, 5],
             [n // 2 + 2, n // 2 - 2, 1, 5]]
    return {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n // 2]],
            "obstacles": {"rects": rects}}


def corridor(n):
    rows = [{"y": y, "runs": [[0, n // 2], [n // 2 + 1, n - n // 2 - 1]]} for y in range(n)]
    return {"grid": {"width": n, "height": n}, "start": [n // 2, 0], "targets": [[n // 2, n - 1]],
            "obstacles": {"rows": rows}, "method": "dbm", "include": ["cells", "tree", "stats"]}


def scaled(mesh, k):
    return {**mesh, "positions": [v * k for v in mesh["positions"]]}


# ---- mutations: a plausible wrong answer made from the real ones (--mutations) -------------------
def mutation(text, change):
    """(text, fn): fn(answers) returns a deep copy of the answers that change(copy) edited in place."""
    def fn(answers):
        wrong = copy.deepcopy(answers)
        change(wrong)
        return wrong
    return text, fn


def with_mutation(check, text, change):
    """A check's own default mutation (a row may still name another)."""
    check.mutation = mutation(text, change)
    return check


def off_values(values):
    """The farthest value in (1e-30, 1) made 1 % smaller; where there is none, the first 0 read as 1
    (the naive overflow: d² = ∞ or 0 taken for no fog), else the last 1 read as 0."""
    inside = [i for i, v in enumerate(values) if 1e-30 < v < 1]
    if inside:
        values[inside[-1]] *= 0.99
    elif 0 in values:
        values[values.index(0)] = 1.0
    else:
        values[-1] = 0.0


OFF_FACTOR = "the farthest f in (0, 1) ×0.99, or a 0 read as 1 (the naive overflow)"


def off_samples(answers, key="factor"):
    samples = answers[0][1]["samples"]
    values = [x[key] for x in samples]
    off_values(values)
    for x, v in zip(samples, values):
        x[key] = v


def parent_pointer(answers):
    err = answers[0][1]["errors"][0]
    err["pointer"] = err["pointer"].rsplit("/", 1)[0] or "/"


# ---- checks: each takes the answers (one per request) and returns (ok, observed) ---------------
def ok_status(status, answers):
    return all(s == status for s, _ in answers)


def near(o, e, tol=2e-6, rel=1e-5):
    """|o − e| within tol, and within rel relative where e is above 1e-30 (so that e^−50 ×1.01 fails)."""
    return abs(o - e) <= tol and (e <= 1e-30 or abs(o / e - 1) <= rel)


def rel_worst(observed, expected):
    return max((abs(o / e - 1) for o, e in zip(observed, expected) if e > 1e-30), default=0.0)


def problem(status, pointer):
    def check(answers):
        s, a = answers[0]
        got = (a.get("errors") or [{}])[0].get("pointer") if isinstance(a, dict) else None
        return s == status and got == pointer, f"{s} at {got}: {(a.get('errors') or [{}])[0].get('message', '')}"
    return with_mutation(check, f"the {status} naming the parent of {pointer}", parent_pointer)


def fog_table(expected_f, tol=2e-6):
    """Every entry of a 1-D table against expected_f(d); HEIGHT tables: expected_f(d, dy)."""
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        t = a["table"]
        f, ds = t["factor"], distances(t)
        if t.get("elevations"):
            rows = t["elevations"]
            exp = [expected_f(d, -1 + 2 * e / (rows - 1)) for e in range(rows) for d in ds]
        else:
            exp = [expected_f(d) for d in ds]
        err, rerr = worst(f, exp), rel_worst(f, exp)
        ok = len(f) == len(exp) and all(near(o, e, tol) for o, e in zip(f, exp))
        return ok, (f"{len(f)} factors in [{min(f):.4g}, {max(f):.4g}]; max |f − closed form| {err:.2g} "
                    f"(relative {rerr:.2g} above 1e-30)")
    return with_mutation(check, OFF_FACTOR, lambda answers: off_values(answers[0][1]["table"]["factor"]))


def fog_transmittance(coefficients):
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        t = a["table"]
        tr, ds = t["transmittance"], distances(t)
        exp = [exp_neg(c, d) for d in ds for c in coefficients]
        err, rerr = worst(tr, exp), rel_worst(tr, exp)
        ok = len(tr) == len(exp) and all(near(o, e) for o, e in zip(tr, exp))
        return ok, (f"T per channel in [{min(tr):.4g}, {max(tr):.4g}]; max |T − e^(−β·d)| {err:.2g} "
                    f"(relative {rerr:.2g} above 1e-30)")
    return with_mutation(check, "the farthest T in (0, 1) ×0.99",
                         lambda answers: off_values(answers[0][1]["table"]["transmittance"]))


def fog_points(case, f, points, must, camera=(0, 0, 0), regions=None, mutated=None):
    """A row of `samples`: each point's region, f, and (ATMOSPHERIC or directional) transmittance and
    fog colour against fog_model's closed forms, within 2e-6 and 1e-5 relative above 1e-30."""
    body = fog(f, samples={"camera": list(camera), "points": points}, include=["samples"])
    if regions:
        body["regions"] = regions
    want = []
    for p in points:
        r = region_of(regions or [], p)
        want.append((r,) + fog_model(body["fog"] if r < 0 else regions[r]["fog"], camera, p))

    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}: {(a.get('errors') or [{}])[0].get('message', '')}"
        got = a["samples"]
        bad, errs, rels = [], [0.0], [0.0]
        for i, (x, (r, fe, te, ce)) in enumerate(zip(got, want)):
            pairs = [(x["factor"], fe)]
            if te is not None:
                pairs += list(zip(x.get("transmittance") or [math.nan] * 3, te))
                pairs += list(zip(x.get("fogColor") or [math.nan] * 3, ce))
            errs += [abs(o - e) for o, e in pairs]
            rels += [abs(o / e - 1) for o, e in pairs if e > 1e-30]
            if x["region"] != r or not all(near(o, e) for o, e in pairs):
                bad.append(f"point {i}: region {x['region']} (want {r}), f {x['factor']:.6g} (want {fe:.6g})")
        fs, rs = ", ".join(f"{x['factor']:.4g}" for x in got), ", ".join(str(x["region"]) for x in got)
        seen = (f"f = {fs}" + (f"; regions {rs}" if regions else "")
                + ("; T and fog colour too" if want[0][2] is not None else "")
                + f"; max |Δ| {max(errs):.2g}, relative {max(rels):.2g}")
        ok = len(got) == len(want) and not bad
        return ok, seen if ok else seen + "; " + "; ".join(bad[:3])
    return ("fog", case, "fog", body, with_mutation(check, OFF_FACTOR, off_samples), must) + ((mutated,) if mutated else ())


def cells_of(a):
    c, dims = a["cells"], len(a["grid"])
    return [tuple(c[i:i + dims]) for i in range(0, len(c), dims)]


def tree_problems(body, a, cells):
    """Every cell inside the grid, none twice, each a neighbour of its parent (2-D or 3-D), the
    tree rooted at the start with parents grown before their children, and the main channel the
    parent chain from the root to a target."""
    grid, tree = a["grid"], a["tree"]
    parent = tree["parent"]
    hood = body.get("neighbourhood", 26 if len(grid) == 3 else 8)
    problems = []
    if len(parent) != len(cells) or not cells or list(cells[0]) != list(body["start"]) or parent[0] != -1:
        problems.append("not a tree rooted at the start")
        return problems
    if any(not all(0 <= c[k] < grid[k] for k in range(len(grid))) for c in cells):
        problems.append("a cell outside the grid")
    if len(set(cells)) != len(cells):
        problems.append("a cell twice")
    for i, q in enumerate(parent[1:], 1):
        if not 0 <= q < i:
            problems.append(f"cell {i}'s parent {q} grew after it")
            break
        d = [abs(cells[i][k] - cells[q][k]) for k in range(len(grid))]
        if max(d) != 1 or (hood in (4, 6) and sum(d) != 1):
            problems.append(f"cell {i} is not a neighbour of its parent")
            break
    main = tree.get("mainChannel")
    if main is not None and (main[0] != 0 or any(parent[m] != p for p, m in zip(main, main[1:]))
                             or list(cells[main[-1]]) not in [list(t) for t in body["targets"]]):
        problems.append("the main channel is not the parent chain from the start to a target")
    return problems


def cell_off(answers):
    """The bolt's last cell moved 3 cells along x: off its parent (or out of the grid)."""
    a = answers[0][1]
    c = a["cells"]
    i = len(c) - len(a["grid"])
    c[i] += 3 if c[i] + 3 < a["grid"][0] else -3


CELL_OFF = "the last cell moved 3 cells along x, off its tree"


def bolt_ok(body, pred=None):
    """Inside the grid, a tree rooted at the start, each cell next to its parent, the target reached;
    then pred(answer)."""
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        cells = cells_of(a)
        problems = tree_problems(body, a, cells)
        if tuple(body["targets"][-1]) not in cells:
            problems.append("target not reached")
        seen = "; ".join(problems) or f"{len(cells)} cells, a connected tree, the target reached"
        ok2, seen2 = pred(a) if pred else (True, "")
        return not problems and ok2, seen + ("; " + seen2 if seen2 else "")
    return with_mutation(check, CELL_OFF, cell_off)


def scale_cells(answers, runs, pick, k):
    for run, (_, a) in zip(runs, answers):
        if pick(run):
            a["stats"]["counters"]["cells"] *= k


def per_row(lengths_seeds, tol=0.12, filled=None):
    """Invariance along a channel: cells per row (cells / length) the same at every length."""
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        by_length = {}
        for (length, _), (_, a) in zip(lengths_seeds, answers):
            by_length.setdefault(length, []).append(a["stats"]["counters"]["cells"] / length)
        means = {L: sum(v) / len(v) for L, v in by_length.items()}
        short, long_ = means[min(means)], means[max(means)]
        ratio = long_ / short
        ok = abs(ratio - 1) <= tol and (filled is None or long_ < filled)
        stages = max(a["stats"]["counters"].get("deepestStage", 0) for _, a in answers)
        return ok, (f"cells per row {short:.3f} at length {min(means)}, {long_:.3f} at {max(means)} (ratio {ratio:.3f}; "
                    f"deepest stage {stages:g})")
    longest = max(L for L, _ in lengths_seeds)
    return with_mutation(check, "the longest bolts 25 % fuller (the far field lost: growth fills behind the tip)",
                         lambda answers: scale_cells(answers, lengths_seeds, lambda r: r[0] == longest, 1.25))


def same_fill(runs):
    """Cells per row at eta 1e-6 against eta 0, per length."""
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        sums = {}
        for (length, eta, _), (_, a) in zip(runs, answers):
            sums.setdefault((length, eta), []).append(a["stats"]["counters"]["cells"] / length)
        seen, ok = [], True
        for length in sorted({L for L, _, _ in runs}):
            zero = sum(sums[(length, 0)]) / len(sums[(length, 0)])
            tiny = sum(sums[(length, 1e-6)]) / len(sums[(length, 1e-6)])
            ok = ok and abs(tiny / zero - 1) <= 0.05
            seen.append(f"length {length}: {zero:.3f} at η 0, {tiny:.3f} at η 1e-6")
        return ok, "; ".join(seen)
    return with_mutation(check, "the η 1e-6 bolts 10 % thinner (underflowed candidates never drawn)",
                         lambda answers: scale_cells(answers, runs, lambda r: r[1] == 1e-6, 0.9))


FLT_MIN = 1.1754943508222875e-38


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


def flip_frame(answers):
    """The first frame flipped: t → −t (still unit and ⟂ n)."""
    t = answers[-1][1]["tangents"]
    t[0:3] = [-x for x in t[0:3]]


def tangents_equal_at_scales(body, scales):
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        ref = answers[0][1]["tangents"]
        err = max(worst(a["tangents"], ref) for _, a in answers[1:])
        probs = [p for (_, a), k in zip(answers, [1] + scales) for p in check_tangents({}, a, None) +
                 frame_problems({"mesh": scaled(body["mesh"], k)}, a)]
        return err <= 1e-6 and not probs, (f"max |t(scale) − t(1)| {err:.2g} at scales {', '.join(f'{k:g}' for k in scales)}"
                                           + ("; " + probs[0] if probs else "; MikkTSpace's frames at every scale"))
    return with_mutation(check, "the first frame flipped at the largest scale", flip_frame)


def unit_frames(body, pred=None):
    """check_tangents (unit, ⟂ n, w = ±1) and frame_problems (the direction and handedness)."""
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        probs = check_tangents({}, a, None) + frame_problems(body, a)
        seen = f"{len(a['tangents']) // 4} unit tangents ⟂ normals, along ∂p/∂u or the fallback" if not probs else probs[0]
        if pred:
            ok2, s2 = pred(a)
            return not probs and ok2, seen + "; " + s2
        return not probs, seen
    return with_mutation(check, "the first frame flipped (t → −t: still unit, ⟂ n)", flip_frame)


def fresnel_r(cos_i, n):
    """The larger of |r_s|, |r_p| from air into index n at incidence cos_i."""
    sin2 = 1 - cos_i * cos_i
    cos_t = math.sqrt(max(0.0, 1 - sin2 / (n * n)))
    rs = (cos_i - n * cos_t) / (cos_i + n * cos_t) if cos_i + n * cos_t > 0 else 1.0
    rp = (n * cos_i - cos_t) / (n * cos_i + cos_t) if n * cos_i + cos_t > 0 else 1.0
    return max(abs(rs), abs(rp))


def faint_film(n2):
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        t = a["thinFilm"]
        w, h, rgb = t["width"], t["height"], t["rgb"]
        worst_ratio, top = 0.0, 0.0
        for row in range(1, h):
            bound = 1.5 * 4 * fresnel_r(row / (h - 1), n2) ** 2
            got = max(abs(v) for v in rgb[3 * row * w:3 * (row + 1) * w])
            top = max(top, got)
            worst_ratio = max(worst_ratio, got / bound)
        finite = all(math.isfinite(v) for v in rgb)
        return finite and worst_ratio <= 1, f"max |rgb| off grazing {top:.2g}; at most {worst_ratio:.2f} of each row's bound"
    return with_mutation(check, "the film's rgb ×2 (its reflectance counted twice)",
                         lambda answers: answers[0][1]["thinFilm"].update(rgb=[2 * v for v in answers[0][1]["thinFilm"]["rgb"]]))


def bubble_scale_invariant(radii):
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        shapes = [[v / r for v in a["mesh"]["positions"]] for r, (_, a) in zip(radii, answers)]
        err = max(worst(s, shapes[0]) for s in shapes[1:])
        return err <= 1e-5, f"max |p/r at radius {radii[1]:g} − p/r at {radii[0]:g}| = {err:.2g}"

    def nudge(answers):
        answers[-1][1]["mesh"]["positions"][0] += 1e-4 * radii[-1]
    return with_mutation(check, f"one vertex nudged by 1e-4 radii at radius {radii[-1]:g}", nudge)


def checked_by_sweep(answers_body):
    body = answers_body

    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        probs = check_bubble(body, a, SERVER)
        return not probs, "every triangle oriented as on the undisturbed sphere, none degenerate" if not probs else probs[0]

    def invert(answers):
        mesh = answers[0][1]["mesh"]
        p, (i, j) = mesh["positions"], mesh["indices"][:2]
        p[3 * i:3 * i + 3], p[3 * j:3 * j + 3] = p[3 * j:3 * j + 3], p[3 * i:3 * i + 3]
    return with_mutation(check, "the first triangle folded over (two of its corners swapped)", invert)


def thin_film_zero_and_air(answers):
    (s1, a1), (s2, a2) = answers
    if s1 != 200 or s2 != 200:
        return False, f"statuses {s1}, {s2}"
    t = a1["thinFilm"]
    w, h, rgb = t["width"], t["height"], t["rgb"]
    # Column 0 (thickness 0): no film, nothing reflected, except at grazing (row 0, cos 0): R = 1.
    col0 = [rgb[3 * (row * w):3 * (row * w) + 3] for row in range(h)]
    zero_ok = all(abs(v) <= 1e-6 for row in col0[1:] for v in row) and all(abs(v - 1) <= 1e-6 for v in col0[0])
    finite = all(math.isfinite(v) for v in rgb)
    air = a2["thinFilm"]["rgb"]
    air_ok = all(abs(v) <= 1e-6 for v in air)
    return zero_ok and finite and air_ok, (f"thickness 0: {max(abs(v) for row in col0[1:] for v in row):.2g} off the "
                                           f"grazing row (1 at grazing); n₂ = 1: max |rgb| {max(abs(v) for v in air):.2g}; "
                                           f"1e4 nm column finite: {finite}")


def zero_film_reflects(answers):
    t = answers[0][1]["thinFilm"]
    t["rgb"][3 * t["width"]] = 0.01  # row 1 (off grazing), column 0 (thickness 0), red


def final_vectors(body):
    """Eqns 4-8 per vertex from the answer's own positions and normals, written out here: I the unit
    ray from the camera, γ = N·V, ν_in = (n1/n2)·√(1 − γ²); Final = R·μ_top + T, R = I + 2γN,
    T = (η·I + (η·γ − γ_in)·N)·μ_bottom while ν_in < 1, else 0 (TIR); α = min(1, 0.05·t)."""
    prm = body["params"]
    n1, n2, cam = prm.get("n1", 1.0), prm.get("n2", 1.33), body["camera"]
    alpha = min(1.0, max(0.0, prm.get("muSpeed", 0.05) * body["time"]))
    mu_top, mu_bottom = 1 + (0.1 - 1) * alpha, 0.1 + (1 - 0.1) * alpha

    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        m = a["mesh"]
        pos, nor, fin = m["positions"], m["normals"], m["finalVectors"]
        err, tir = 0.0, 0
        for v in range(len(pos) // 3):
            i = ray(cam, pos[3 * v:3 * v + 3])[1]
            nn = ray([0, 0, 0], nor[3 * v:3 * v + 3])[1]
            g = -sum(x * y for x, y in zip(i, nn))
            nu_in = n1 / n2 * math.sqrt(max(0.0, 1 - g * g))
            want = [(x + 2 * g * y) * mu_top for x, y in zip(i, nn)]
            if nu_in < 1:
                eta, g_in = n1 / n2, math.sqrt(1 - nu_in * nu_in)
                want = [w + (eta * x + (eta * g - g_in) * y) * mu_bottom for w, x, y in zip(want, i, nn)]
            else:
                tir += 1
            err = max([err] + [abs(x - y) for x, y in zip(fin[3 * v:3 * v + 3], want)])
        finite = all(math.isfinite(v) for v in fin)
        return finite and err <= 1e-5 and tir > 0, (f"{len(fin) // 3} final vectors ({tir} past the critical angle); "
                                                    f"max |Final − eqn 8| {err:.2g}")

    def unweighted(answers):
        f = answers[0][1]["mesh"]["finalVectors"]
        f[0:3] = [x / mu_top for x in f[0:3]]
    return with_mutation(check, "one final vector without eqn 8's weight μ_top", unweighted)


def drained_film(h_nm):
    """A film drained to H(t) = h_nm: every texel in [0, H] (h = H·√s, s in [0, 1], wherever the
    swirl brought the film from), finite, and its bottom near H (max ≥ 0.9 H)."""
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        nm = a["thickness"]["nm"]
        ok = all(math.isfinite(v) and 0 <= v <= h_nm * (1 + 1e-6) for v in nm) and max(nm) >= 0.9 * h_nm
        return ok, f"thickness in [{min(nm):.4g}, {max(nm):.4g}] nm (H = {h_nm:g} nm)"
    return with_mutation(check, "the undrained film's thickness (H = 1000 nm: ×10/3)",
                         lambda answers: answers[0][1]["thickness"].update(nm=[v * 10 / 3 for v in answers[0][1]["thickness"]["nm"]]))


def bolts_equal(bodies, text):
    """Every bolt a tree rooted at the start that reaches the target, and all the same, cell for cell."""
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        probs = [p for b, (_, a) in zip(bodies, answers) for p in tree_problems(b, a, cells_of(a))]
        probs += ["target not reached" for b, (_, a) in zip(bodies, answers) if tuple(b["targets"][-1]) not in cells_of(a)]
        same = all(a["cells"] == answers[0][1]["cells"] for _, a in answers[1:])
        return not probs and same, (probs[0] if probs else f"{len(cells_of(answers[0][1]))} cells, a connected tree; "
                                    + (text if same else "NOT " + text))
    return check


def regrown(body, text):
    """A mutation that asks the server for the bolt a plausible mistake would give."""
    def change(answers):
        s, a, _ = SERVER.post("/v1/lightning", body)
        answers[0] = (s, a if isinstance(a, dict) else {})
    return mutation(text, change)


# ---- warped HEIGHT tables (docs/using/fog.md §4; fog.h WarpedAxes) -------------------------------
def warped_row_y(axes, v):
    """Row v in [0, 1] -> the ray's y: the inverse of v = 1/2 + asinh(k y)/(2 asinh k)."""
    k = axes["k"]
    return min(1.0, max(-1.0, math.sinh(math.asinh(k) * (2 * v - 1)) / k))


def warped_span(axes, y, start):
    """The column span of the row at y (common.json's fogTable.axes, written out)."""
    full = max(axes["end"] - start, 0.0)
    if not y < 0 or not axes["kappa"] > 0:
        return full
    big_k = axes["kappa"] * math.exp(axes["falloff"] * y * start)
    x = -big_k * y
    own = axes["lambda"] * big_k * (math.log1p(x) / x if x > 0 else 1.0)
    lo, hi = min(full, own), max(full, own)
    return lo * (1 + (lo / hi) ** 8) ** (-1 / 8) if hi > 0 else 0.0


def warped_table(bodies):
    """Every entry of warped HEIGHT tables against height_f at the (distance, y) that the answer's
    axes put it at (row v_j = j/(rows − 1) -> y = sinh((2v − 1)·asinh k)/k; column u_i = i/(size − 1)
    -> d = start + u·span(y)); the axes checked against the request where the request fixes them
    (falloff, range, k in [1, 1e6]); and each row long enough: a lookup past its last column
    clamps there, which is within 1/255 of the closed form out to the range's end (docs/using/fog.md
    §5) only if f(last column) − f(end) ≤ 1/255 (f falls with d)."""
    def check(answers):
        seen, bad, n, errs, rels, lo = [], [], 0, [0.0], [0.0], math.inf
        for body, (s, a) in zip(bodies, answers):
            if s != 200:
                return False, f"status {s}: {(a.get('errors') or [{}])[0].get('message', '')}"
            f, req, t = body["fog"], body["table"], a["table"]
            ax = t.get("axes") or {}
            cam = req["cameraHeight"]
            if t.get("layout") != "warped" or not ax:
                return False, "no warped layout or axes in the answer"
            start, end = t["range"]
            if ax["falloff"] != f["heightFalloff"] or ax["factorStart"] != start or ax["end"] != end \
                    or not 1 <= ax["k"] <= 1e6 or ("range" in req and t["range"] != req["range"]):
                bad.append(f"axes {ax} against the request's falloff {f['heightFalloff']:g} and range {t['range']}")
            width, rows = t["size"], t["elevations"]
            fac = t["factor"]
            if len(fac) != width * rows:
                return False, f"{len(fac)} factors for {width} × {rows}"
            for j in range(rows):
                y = warped_row_y(ax, j / (rows - 1))
                span = warped_span(ax, y, ax["factorStart"])
                last = end if span >= end - ax["factorStart"] else ax["factorStart"] + span
                for i in range(width):
                    d = last if i == width - 1 else ax["factorStart"] + span * i / (width - 1)
                    o, e = fac[j * width + i], height_f(f["density"], f["heightFalloff"], f.get("baseHeight", 0), cam, y, d)
                    errs.append(abs(o - e))
                    if e > 1e-30:
                        rels.append(abs(o / e - 1))
                    if not near(o, e):
                        bad.append(f"row {j} (y {y:.6g}), column {i} (d {d:.6g}): f {o:.7g}, closed form {e:.7g}")
                beyond = fac[j * width + width - 1] - height_f(f["density"], f["heightFalloff"], f.get("baseHeight", 0), cam, y, end)
                if beyond > 1 / 255 + 2e-6:
                    bad.append(f"row {j} (y {y:.6g}) ends at d = {last:.6g} with f {fac[j * width + width - 1]:.4g}: "
                               f"{beyond:.4g} above the closed form at the range's end {end:.6g}")
                lo = min(lo, span)
            n += len(fac)
            seen.append(f"{width} × {rows} (k {ax['k']:.4g}, κ {ax['kappa']:.4g}, λ {ax['lambda']:.4g}; f in "
                        f"[{min(fac):.3g}, {max(fac):.3g}])")
        text = (f"{'; '.join(seen)}: {n} entries at their warped (d, y), shortest span {lo:.3g}; max |f − closed form| "
                f"{max(errs):.2g} (relative {max(rels):.2g} above 1e-30); past each row's last column f falls by at most 1/255")
        return not bad, text if not bad else text + "; " + "; ".join(bad[:3])

    def linear(answers):  # the same requests in the linear layout: its entries under warped axes
        for k, body in enumerate(bodies):
            lin = copy.deepcopy(body)
            lin["table"]["layout"] = "linear"
            s, a, _ = SERVER.post("/v1/fog", lin)
            answers[k][1]["table"]["factor"] = a["table"]["factor"]
    check.mutation = mutation("the linear table's entries (the layout ignored) under the warped axes", linear)
    return check


def warped(f, size, rows, camera_height, rng=None):
    table = {"size": size, "elevations": rows, "cameraHeight": camera_height, "layout": "warped"}
    if rng:
        table["range"] = rng
    return fog(f, table=table)


def warped_rows():
    w1 = [warped(HEIGHT, 64, 32, 2)]
    w2 = [warped({**HEIGHT, "density": 1e300}, 32, 16, c, [0, 100]) for c in (3, -3)]
    w3 = [warped({**HEIGHT, "heightFalloff": 100}, 32, 16, 0.5)]
    w4 = [warped(HEIGHT, 32, 16, 300, [0, 1e5])]
    w5 = [warped(HEIGHT, 32, 16, 1000, [0, 1e5])]
    return [
        ("fog", "HEIGHT, warped 64 × 32, camera at 2", "fog", w1, warped_table(w1),
         "every entry = height_f at the (d, y) its axes give, within 2e-6 and 1e-5 relative (float32); each row "
         "out to its fog's completeness or the range's end"),
        ("fog", "HEIGHT, warped, density 1e300, camera 3 above and 3 below the layer", "fog", w2, warped_table(w2),
         "downward rows' columns 1e-299 long (κ at its e^−690 floor), f at each = height_f; level and rising rows "
         "0 past d = 0; every row out to completeness"),
        ("fog", "HEIGHT, warped, falloff 100 (a 1 cm layer), camera 0.5 above it", "fog", w3, warped_table(w3),
         "κ = e^59: the straight-down row's columns end 0.89 away, past the layer; the level and rising rows reach "
         "the default range's end (5.7e23, where the level ray's fog is complete); every entry = height_f"),
        ("fog", "HEIGHT, warped, camera 300 above the layer, range [0, 1e5]", "fog", w4, warped_table(w4),
         "σ at the camera e^−60·a: the downward rows' columns run past where they reach the layer; every entry = "
         "height_f, none short of the fog's completeness"),
        ("fog", "HEIGHT, warped, camera 1000 above the layer, range [0, 1e5]", "fog", w5, warped_table(w5),
         "κ would be e^203, beyond a float: κ 0 (even columns), so every downward row runs to the range's end and "
         "meets the fog (κ clamped at e^69 ended them short at f = 1); every entry = height_f"),
    ]


# ---- Unreal's convention (docs/effects.md §2.4, U1-U4) -------------------------------------------
UNREAL = {"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 1e-4, "baseHeight": 0, "convention": "unreal"}


def effectd_instead(f, camera, points):
    """A mutation: each sample's f as effectd's exact integral would give it (the convention ignored)."""
    ef = {k: v for k, v in f.items() if k != "convention"}

    def change(answers):
        for x, p in zip(answers[0][1]["samples"], points):
            x["factor"] = fog_model(ef, camera, p)[0]
    return mutation("effectd's exact integral (the convention ignored)", change)


def unreal_rows():
    high = (0, 1e6, 0)
    high_pts = [[1e200, 1e199, 0], [3e199, 4e199, 0], [1e5, 1e6, 0], [0, 0, 0]]
    steep = {**UNREAL, "density": 1e-42}
    steep_pts = [[0, -1e6, 0], [0, -1e7, 0], [1e6, -1e6, 0], [5e41, 0, 0]]
    ub = {**UNREAL, "density": 1e300}
    ub_pts = [[1e-300, 0, 0], [0, 0, 2e-300], [1e200, 1e200, 0]]
    ef = {k: v for k, v in UNREAL.items() if k != "convention"}
    fu = ", ".join(f"{unreal_f(UNREAL, high, p):.3g}" for p in high_pts)
    eu = ", ".join(f"{fog_model(ef, high, p)[0]:.3g}" for p in high_pts)
    fs = ", ".join(f"{unreal_f(steep, (0, 0, 0), p):.3g}" for p in steep_pts)
    es = ", ".join(f"{fog_model({**ef, 'density': 1e-42}, (0, 0, 0), p)[0]:.3g}" for p in steep_pts)
    ut = {**UNREAL, "color": [0.7, 0.75, 0.8]}
    return [
        fog_points("HEIGHT in Unreal's convention, camera 1e6 above the layer, points to 1e200", UNREAL, high_pts,
                   f"Unreal's f from its observer lowered to 65536 (U4): f = {fu} (effectd's from the camera: {eu})",
                   camera=high, mutated=effectd_instead(UNREAL, high, high_pts)),
        fog_points("HEIGHT in Unreal's convention, density 1e-42, falls of 1e6 and 1e7", steep, steep_pts,
                   f"B·v_y clamped at −127 (U3) on the falls, the Taylor term on the level ray (U2): f = {fs} "
                   f"(effectd: {es})",
                   mutated=effectd_instead(steep, (0, 0, 0), steep_pts)),
        fog_points("HEIGHT in Unreal's convention, density 1e300, points 1e-300 … 1.4e200 away", ub, ub_pts,
                   "A'·L from 1e300·2^0 and 1e-300: f = " + ", ".join(f"{unreal_f(ub, (0, 0, 0), p):.3g}" for p in ub_pts),
                   mutated=mutation("the farthest f in (0, 1) ×0.99", off_samples)),
        ("fog", "HEIGHT in Unreal's convention: table, camera 1e5 (observer at 65536), range [0, 1e6]", "fog",
         fog(ut, table={"size": 32, "elevations": 9, "cameraHeight": 1e5, "range": [0, 1e6], "layout": "linear"}),
         fog_table(lambda d, dy: unreal_f(ut, (0, 1e5, 0), (d * math.sqrt(max(0.0, 1 - dy * dy)), 1e5 + d * dy, 0))),
         "every entry = Unreal's f (U2-U4 written out here) within 2e-6 and 1e-5 relative (float32)"),
    ]


# ---- /v1/scene: each part as its own endpoint answers it ----------------------------------------
def scene_parts(scene_body, parts, fog_check):
    """The scene's answer holds exactly the parts asked for, each equal (as parsed JSON) to the
    standalone endpoint's answer for the same body; the fog part also against its closed form, the
    bolt a connected tree to its target."""
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        scene = answers[0][1]
        probs = [] if set(scene) == set(parts) else [f"parts {sorted(scene)}, asked for {sorted(parts)}"]
        probs += [f"the scene's {p} differs from /v1/{p}'s" for p, (_, a) in zip(parts, answers[1:]) if scene.get(p) != a]
        ok_fog, seen_fog = fog_check([(200, scene.get("fog", {}))])
        if not ok_fog:
            probs.append("fog against its closed form: " + seen_fog)
        probs += tree_problems(scene_body["lightning"], scene["lightning"], cells_of(scene["lightning"]))
        m = scene["bubble"]["mesh"]
        seen = (f"fog, lightning ({len(cells_of(scene['lightning']))} cells) and bubble ({len(m['positions']) // 3} "
                f"vertices) equal to /v1/fog's, /v1/lightning's and /v1/bubble's; fog: {seen_fog}")
        return not probs, seen if not probs else "; ".join(probs[:3])

    def nudge(answers):
        p = answers[0][1]["bubble"]["mesh"]["positions"]
        p[0] += 1e-6 * scene_body["bubble"]["mesh"]["radius"]
    check.mutation = mutation("the scene's bubble: one vertex nudged by 1e-6 of its radius", nudge)
    return check


def scene_rows():
    fr = fog_points("", {**HEIGHT, "density": 1e300, "heightFalloff": 1e300},
                    [[3e-300, 5e-300, 0], [3e-300, -3e-300, 0], [5e-300, 1e-300, 0]], "", camera=(0, 1e-300, 0))
    scene = {"fog": fr[3], "lightning": {**bolt(48, eta=50, seed=7), "include": ["cells", "tree"]},
             "bubble": {"time": 1e9, "mesh": {"level": 2, "radius": 1e-6}, "include": ["mesh"]}}
    parts = ["fog", "lightning", "bubble"]
    return [("scene", "fog 1e300 over 5e-300, bolt at η 50, bubble of radius 1e-6 at t = 1e9", ["scene"] + parts,
             [scene] + [scene[p] for p in parts], scene_parts(scene, parts, fr[4]),
             "each part of the scene's answer equal (as parsed JSON) to its endpoint's answer for the same body; the "
             "fog's f = height_f (0.64, 2e-11, 0.16); the bolt a connected tree to its target")]


# ---- /v1/render: the preview's pixels against the reference renderer ----------------------------
def png_decode(data):
    """(width, height, channels, depth, rows): an 8- or 16-bit PNG (grey, RGB, grey + alpha or RGBA,
    not interlaced) inflated with zlib and its five filter types undone; rows[y][x·channels + c] in
    [0, 1]. The CRC of every chunk is checked."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, ihdr = 8, [], None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        chunk = data[pos + 8:pos + 8 + n]
        if zlib.crc32(kind + chunk) != struct.unpack(">I", data[pos + 8 + n:pos + 12 + n])[0]:
            raise ValueError(f"bad CRC in {kind!r}")
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", chunk)
        elif kind == b"IDAT":
            idat.append(chunk)
        elif kind == b"IEND":
            break
        pos += 12 + n
    w, h, depth, ctype, _, _, interlace = ihdr
    channels = {0: 1, 2: 3, 4: 2, 6: 4}[ctype]
    if depth not in (8, 16) or interlace:
        raise ValueError(f"bit depth {depth}, interlace {interlace}: not decoded here")
    bpp = channels * depth // 8  # bytes per pixel: the filters' left neighbour
    stride = w * bpp
    raw = zlib.decompress(b"".join(idat))
    prev, rows = bytearray(stride), []
    for y in range(h):
        ftype, line = raw[y * (stride + 1)], bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            elif ftype != 0:
                raise ValueError(f"filter type {ftype}")
        prev = line
        rows.append([v / 255 for v in line] if depth == 8 else [v / 65535 for v in struct.unpack(f">{stride // 2}H", line)])
    return w, h, channels, depth, rows


def png_encode(w, h, channels, depth, rows):
    """The inverse (filter 0 throughout): a mutation's edited image sent back through the check."""
    top = 255 if depth == 8 else 65535
    raw = bytearray()
    for r in rows:
        vals = [min(top, max(0, round(v * top))) for v in r]
        raw += b"\x00" + (bytes(vals) if depth == 8 else struct.pack(f">{len(vals)}H", *vals))

    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body))
    ctype = {1: 0, 3: 2, 2: 4, 4: 6}[channels]
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, depth, ctype, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(bytes(raw))) + chunk(b"IEND", b""))


def rgb_pixels(png):
    w, h, c, _, rows = png_decode(png)
    return w, h, [tuple(rows[y][x * c:x * c + 3]) for y in range(h) for x in range(w)]


def sphere_pixels(scene):
    """Which pixels' centre rays meet the bubble's sphere: the closed form, from the scene's camera
    (look-at, fovY, the aspect), the bubble's radius and bubbleStyle.center."""
    cam = scene["camera"]
    eye, target = cam["position"], cam.get("target", [0, 0.5, 0])
    w, h = scene["width"], scene["height"]

    def unit(v):
        n = math.hypot(*v)
        return [x / n for x in v]

    def cross(a, b):
        return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    fw = unit([b - a for a, b in zip(eye, target)])
    right = unit(cross(fw, cam.get("up", [0, 1, 0])))
    up = cross(right, fw)
    ty = math.tan(math.radians(cam.get("fovY", 45)) / 2)
    tx = ty * w / h
    centre, r = scene.get("bubbleStyle", {}).get("center", [0, 0, 0]), scene["bubble"]["mesh"]["radius"]
    oc = [(a - b) / r for a, b in zip(eye, centre)]  # in radii: the same sums at radius 1e-6 and 1e6
    out = []
    for y in range(h):
        for x in range(w):
            nx, ny = 2 * (x + 0.5) / w - 1, 1 - 2 * (y + 0.5) / h
            d = unit([f + nx * tx * a + ny * ty * b for f, a, b in zip(fw, right, up)])
            half = sum(a * b for a, b in zip(oc, d))
            disc = half * half - (sum(a * a for a in oc) - 1)
            out.append(disc > 0 and -half - math.sqrt(disc) > 0)
    return out


def delta_e(p, q):
    """CIE76 ΔE*ab between two sRGB colours (D65), as docs/error-vs-time.md measures the render previews."""
    def lab(rgb):
        r, g, b = (c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4 for c in rgb)
        xyz = (0.4124 * r + 0.3576 * g + 0.1805 * b) / 0.95047, 0.2126 * r + 0.7152 * g + 0.0722 * b, \
            (0.0193 * r + 0.1192 * g + 0.9505 * b) / 1.08883
        fx, fy, fz = (t ** (1 / 3) if t > (6 / 29) ** 3 else t / (3 * (6 / 29) ** 2) + 4 / 29 for t in xyz)
        return 116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)
    return math.dist(lab(p), lab(q))


RENDER_BOUND = 5 / 255  # mean |preview − reference| per channel over the sphere's pixels


def render_matches_reference(scene, moved=None):
    """Bodies: the preview (/v1/render), the reference (reference: true) and the backdrop alone (the
    scene without its bubble). Silhouette: where each image differs from the backdrop (by 1.5/255 or
    more on a channel) is the sphere's closed-form silhouette, but for pixels on its edge (a 3 × 3
    neighbourhood that straddles it: the mesh's polygon outline). Colour: the mean |preview −
    reference| per channel over the sphere's pixels at most RENDER_BOUND (5/255)."""
    disk = sphere_pixels(scene)
    w, h = scene["width"], scene["height"]
    edge = [any(disk[yy * w + xx] != disk[y * w + x] for yy in range(max(0, y - 1), min(h, y + 2))
                for xx in range(max(0, x - 1), min(w, x + 2))) for y in range(h) for x in range(w)]
    inside = [i for i in range(w * h) if disk[i]]

    def check(answers):
        if not ok_status(200, answers) or not all(isinstance(a, bytes) for _, a in answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        (pw, ph, pre), (rw, rh, ref), (_, _, bg) = (rgb_pixels(a) for _, a in answers)
        if (pw, ph, rw, rh) != (w, h, w, h):
            return False, f"{pw} × {ph} and {rw} × {rh} pixels, {w} × {h} asked for"
        masks = [[max(abs(p - q) for p, q in zip(img[i], bg[i])) >= 1.5 / 255 for i in range(w * h)] for img in (pre, ref)]
        off = [sum(1 for i in range(w * h) if m[i] != disk[i] and not edge[i]) for m in masks]
        apart = sum(1 for a, b in zip(*masks) if a != b)
        mad = sum(abs(p - q) for i in inside for p, q in zip(pre[i], ref[i])) / (3 * len(inside))
        de = sum(delta_e(pre[i], ref[i]) for i in inside) / len(inside)
        ok = off == [0, 0] and 0 < mad <= RENDER_BOUND
        return ok, (f"{len(inside)} pixels in the sphere's silhouette (closed form): preview and reference differ from "
                    f"the backdrop there, off it {off[0]} and {off[1]} pixels away from its edge, {apart} apart (on the "
                    f"edge); mean |preview − reference| {mad * 255:.2f}/255 per channel (bound "
                    f"{RENDER_BOUND * 255:g}), mean ΔE*ab {de:.2f}")

    def edit(text, fn):
        def change(answers):
            pw, ph, c, depth, rows = png_decode(answers[0][1])
            fn(pw, ph, c, rows)
            answers[0] = (answers[0][0], png_encode(pw, ph, c, depth, rows))
        return mutation(text, change)

    def brighter(pw, ph, c, rows):
        for i in inside:
            y, x = divmod(i, pw)
            rows[y][x * c:x * c + 3] = [min(1.0, 1.2 * v) for v in rows[y][x * c:x * c + 3]]

    def shifted(pw, ph, c, rows):
        for r in rows:
            r[moved * c:] = r[:len(r) - moved * c]

    check.mutation = (edit("the preview's bubble ×1.2 brighter", brighter) if moved is None else
                      edit(f"the preview moved {moved} pixels right", shifted))
    return check


def bubble_scene(radius=1.0, near=None, far=None, depth=8):
    cam = {"position": [0, 0.3 * radius, 4 * radius], "target": [0, 0, 0], "fovY": 45}
    if near:
        cam.update(near=near, far=far)
    return {"width": 96, "height": 96, "bitDepth": depth, "time": 7, "camera": cam,
            "background": {"gradient": {"top": [0.18, 0.24, 0.2], "bottom": [0.08, 0.1, 0.07]}},
            "environment": {"zenith": [0.35, 0.6, 1.0], "horizon": [1.0, 0.98, 0.95], "ground": [0.16, 0.18, 0.12]},
            "bubble": {"mesh": {"level": 4, "radius": radius}, "film": {"seed": 3}, "features": {"wobble": False}}}


def render_rows():
    out = []
    for name, scene, moved in (
            ("examples/03's bubble, 96 × 96", bubble_scene(), None),
            ("radius 1e-6 seen from 4e-6 (near 1e-7, far 1e-5), 16-bit PNG", bubble_scene(1e-6, 1e-7, 1e-5, 16), 3),
            ("radius 1e6 seen from 4e6 (near 1e5, far 1e7)", bubble_scene(1e6, 1e5, 1e7), 3),
            ("radius 1 seen from 4, near 1e-7 and far 1e7 (a depth range of 1e14)", bubble_scene(1, 1e-7, 1e7), 3)):
        backdrop = {k: v for k, v in scene.items() if k != "bubble"}
        out.append(("render", f"preview against the reference: {name}", "render",
                    [scene, {**scene, "reference": True}, backdrop], render_matches_reference(scene, moved),
                    "the bubble on the sphere's closed-form silhouette in both (all but its edge pixels); mean "
                    "|preview − reference| ≤ 5/255 per channel over it (measured 3.2; docs/error-vs-time.md: mean "
                    "ΔE*ab about 3 for this shading, about 1 level of 255 per ΔE here; a 1-pixel shift gives 6.2)"))
    return out


# (effect, case, endpoint, bodies, check, what must hold[, mutation]); bodies may be a list (invariances);
# endpoint may be a list too, one per body.
HEIGHT = {"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0}


def fog_sample_rows():
    """`samples` at the ends of the double range: lengths of 1e-300 and 1e200 (whose squares are 0
    and ∞), densities of 1e300 against distances of 1e-300, regions of radius 1e-200 and 1e200."""
    dc = 5e-324  # the smallest denormal (4.94e-324)
    far = [[5e161, 0, 0], [0, 1e162, 0], [0, 0, 2e162], [3e161, 0, 0]]
    far_f = ", ".join(f"{exp_neg(dc, d, d):.3g}" for d in (5e161, 1e162, 2e162, 3e161))
    fil_tiny = {**HEIGHT, "density": 5e299, "heightFalloff": 1e296, "convention": "filament"}
    tiny_pt = [8e-300, 6e-300, 0]  # d = 1e-299, rise 6e-300: |b·v_y| = 6e-4, under Filament's 0.00125
    effectd_f = height_f(5e299, 1e296, 0, 0, 0.6, 1e-299)
    big = {"sphere": {"center": [0, 0, 0], "radius": 1e200}, "fog": {"fogType": "GL_EXP", "density": 1e-200, "color": [0.2, 0.3, 0.4]}}
    small = {"sphere": {"center": [2e-200, 0, 0], "radius": 1e-200}, "fog": {"fogType": "GL_EXP", "density": 1e200}}

    def first_region(answers):  # the point inside both spheres given to the first that holds it
        answers[0][1]["samples"][0].update(region=0, factor=exp_neg(1e-200, 2e-200))
    return [
        fog_points("GL_EXP, density 1e300, points 1e-300 … 3e-300 away", {"fogType": "GL_EXP", "density": 1e300},
                   [[1e-300, 0, 0], [0, 2e-300, 0], [1e-300, -1e-300, 0], [0, 0, -3e-300]],
                   "f = e^(−ρ·d) = e^−1, e^−2, e^−√2, e^−3: |p − c| with no square of 1e-300 (a naive one is 0: f = 1)"),
        fog_points("GL_EXP2, density 1e-200, points 1e200 and 5e199 away", {"fogType": "GL_EXP2", "density": 1e-200},
                   [[1e200, 0, 0], [0, 5e199, 0], [-6e199, 0, 8e199]],
                   "f = e^(−(ρ·d)²) = e^−1, e^−0.25, e^−1: d² = 1e400 never formed"),
        fog_points("HEIGHT, level rays 1e150, 1e160, 1e200 away", HEIGHT,
                   [[1e150, 0, 0], [0, 0, 1e160], [1e200, 0, 0], [-1e200, 0, 1e200]],
                   "τ = a·d on level rays at the layer's base: f = 0 (a naive |p − c| = ∞ gives 1)"),
        fog_points("HEIGHT, density 1e170, points 1e-170 and 2e-170 away", {**HEIGHT, "density": 1e170},
                   [[1e-170, 0, 0], [0, 0, -2e-170]], "τ = a·d = 1, 2: f = e^−1, e^−2"),
        fog_points("DISTANCE_EXP2, d_c = 5e-324 (the denormal), d = 5e161 … 2e162", {"fogType": "DISTANCE_EXP2",
                   "distanceCoefficient": dc}, far, f"f = exp(−exp(ln d_c + 2 ln d)) = {far_f}: d² overflows past 1.3e154"),
        fog_points("DISTANCE_GAUSSIAN, d_c = 5e-324, peak 0.5, d = 5e161 … 2e162",
                   {"fogType": "DISTANCE_GAUSSIAN", "distanceCoefficient": dc, "peak": 0.5}, far, "f = peak·exp(−d_c·d²), in log space"),
        fog_points("EXPONENTIAL (X3D), visibilityRange 1e-300", {"fogType": "EXPONENTIAL", "visibilityRange": 1e-300},
                   [[3e-301, 4e-301, 0], [2.5e-301, 0, 0], [0, 9e-301, 0], [0, 0, 2e-300]],
                   "f = exp(−d/(V − d)) = e^−1, e^−1/3, e^−9, then 0 past V"),
        fog_points("EXPONENTIAL (X3D), visibilityRange 1e300", {"fogType": "EXPONENTIAL", "visibilityRange": 1e300},
                   [[3e299, 4e299, 0], [2.5e299, 0, 0], [0, 9e299, 0], [1e300, 1e300, 0]],
                   "f = exp(−d/(V − d)) = e^−1, e^−1/3, e^−9, then 0 past V"),
        fog_points("LINEAR (X3D), visibilityRange 1e-300", {"fogType": "LINEAR", "visibilityRange": 1e-300},
                   [[1.5e-301, 2e-301, 0], [0, 5e-301, 0], [0, 0, 2e-300]], "f = (V − d)/V = 0.75, 0.5, 0"),
        fog_points("LINEAR (X3D), visibilityRange 1e300", {"fogType": "LINEAR", "visibilityRange": 1e300},
                   [[1.5e299, 2e299, 0], [0, 5e299, 0], [1e300, 1e300, 0]], "f = (V − d)/V = 0.75, 0.5, 0"),
        fog_points("GL_LINEAR, start 1e-300, end 3e-300", {"fogType": "GL_LINEAR", "start": 1e-300, "end": 3e-300},
                   [[5e-301, 0, 0], [0, 2e-300, 0], [1.5e-300, 2e-300, 0], [0, 0, 4e-300]],
                   "clamp((end − d)/(end − start)) = 1, 0.5, 0.25, 0"),
        fog_points("GL_LINEAR, start 1e299, end 1e300, camera at x = −5e299", {"fogType": "GL_LINEAR", "start": 1e299, "end": 1e300},
                   [[0, 0, 0], [5e299, 0, 0], [-5e299, 3e299, 4e299], [-5e299, 5e298, 0]],
                   "clamp((end − d)/(end − start)) = 5/9, 0, 5/9, 1", camera=(-5e299, 0, 0)),
        fog_points("ATMOSPHERIC, extinction 1e-300, 1, 300, inscattering 300, 1, 1e-300, d = 1e-300 … 1.7e300",
                   {"fogType": "ATMOSPHERIC", "extinction": [1e-300, 1, 300], "inscattering": [300, 1, 1e-300]},
                   [[1e-300, 0, 0], [0, 2e-3, 0], [3e299, 4e299, 0], [1e300, 0, 0], [1e300, 1e300, 1e300]],
                   "per channel T = e^(−β_e·d) (e^−1 at β 1e-300, d 1e300), fog colour = color·(1 − e^(−β_i·d)); f = mean T"),
        fog_points("GL_EXP 1e300 with a sun (exponent 2, direction 1e-300 long), d = 1e-300 …",
                   {"fogType": "GL_EXP", "density": 1e300,
                    "directional": {"color": [1, 0.8, 0.6], "direction": [0, 0, -1e-300], "exponent": 2}},
                   [[0, 0, -1e-300], [1e-300, 0, -1e-300], [0, 2e-300, 0]],
                   "T = f per channel; fog colour = (1 − f)·(color + sun·max(cos θ, 0)²): lobes 1, 0.5, 0"),
        fog_points("GL_EXP2 1e-200 with a sun (Henyey–Greenstein g 0.5, direction 1e300 long), d = 5e199 …",
                   {"fogType": "GL_EXP2", "density": 1e-200,
                    "directional": {"color": [1, 0.8, 0.6], "direction": [1e300, 0, 0], "g": 0.5}},
                   [[1e200, 0, 0], [0, 1e200, 0], [-5e199, 0, 0]],
                   "fog colour = (1 − f)·(color + sun·(1 − g²)/(1 + g² − 2g cos θ)^1.5): lobes 6, 0.54, 0.22"),
        fog_points("HEIGHT, slanted rays 5e199 … 1e200 long", HEIGHT, [[1e200, 1e199, 0], [1e200, -1e199, 0], [3e199, 4e199, 0]],
                   "height_f with d_y from a scaled norm: rising rays see τ → a/(b·d_y) (f = 0.081, 0.73), "
                   "the falling one f = 0"),
        fog_points("HEIGHT, density and falloff 1e300, rays 5e-300 long, camera 1e-300 up",
                   {**HEIGHT, "density": 1e300, "heightFalloff": 1e300},
                   [[3e-300, 5e-300, 0], [3e-300, -3e-300, 0], [5e-300, 1e-300, 0]],
                   "height_f: b·d_y·t = ±4 and 0 (f = 0.64, 2e-11, 0.16): every product of a 1e300 and a 1e-300 in log space",
                   camera=(0, 1e-300, 0)),
        fog_points("HEIGHT in Filament's convention, 1e-299 away (|b·v_y| = 6e-4)", fil_tiny, [tiny_pt],
                   f"Filament's f = e^(−σ(c_y)·d) = e^−5 below its 0.00125 guard (§2.4 F2), not the exact {effectd_f:.6g}",
                   mutated=mutation(f"effectd's exact integral {effectd_f:.6g} (the convention ignored)",
                                    lambda answers: answers[0][1]["samples"][0].update(factor=effectd_f))),
        fog_points("HEIGHT in Filament's convention, 5e199 … 1e200 away", {**HEIGHT, "convention": "filament"},
                   [[1e200, 1e199, 0], [3e199, 4e199, 0], [1e200, -1e-3, 0]],
                   "Filament's τ = σ(c_y)·d·(1 − e^(−b·v_y))/(b·v_y): f = 0.081, 0.73, and 0 on the near-level ray"),
        fog_points("regions: spheres of radius 1e200 and 1e-200 (nested)", {"fogType": "GL_EXP2", "density": 1e-200},
                   [[2e-200, 0, 0], [2e-200, 5e-201, 0], [2e-200, 1.5e-200, 0], [5e199, 5e199, 0], [1e200, 1e200, 0]],
                   "the innermost region (log volumes: 1e-600 against 1e600): 1, 1, 0, 0, −1 (global), each with its own "
                   "fog: f = e^−2, e^−2.06, 1, e^−0.71, e^−2", regions=[big, small],
                   mutated=mutation("the point inside both spheres given to the first (region 0)", first_region)),
    ]


FRAMES = ["tangents", "normals", "indices", "remap"]


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


def side_branch(answers):
    """Ten cells grown sideways from the fast bolt's middle cell, each a child of the one before."""
    a = answers[0][1]
    cells, parent = a["cells"], a["tree"]["parent"]
    n = len(cells) // 2
    x, y = cells[n // 2 * 2], cells[n // 2 * 2 + 1]
    for k in range(1, 11):
        cells += [x + k if x + 10 < a["grid"][0] else x - k, y]
        parent.append(n // 2 if k == 1 else n + k - 2)


def cases(quick):
    channel_long = 512 if quick else 4096  # 3 x 65536 (the grid limit) would take about 25 min a bolt
    seeds_long = 1 if quick else 2
    charges_power = 5.2 * 2 ** 0.7 * (64 / 128) ** 0.2  # the calibration's law (docs/effects.md §1.3)
    uniform = [bolt(64, eta=0, method=m) for m in ("fast", "dbm", "charges")]
    charges_pair = [bolt(64, method="charges"), bolt(64, method="charges", variant="paper", eta=charges_power)]
    examples = os.path.join(ROOT, "proto/examples/tangents")
    degenerate = {**json.load(open(os.path.join(examples, "04-degenerate-triangles.json"))), "include": FRAMES + ["stats"]}
    mirrored = json.load(open(os.path.join(examples, "02-mirrored-uvs-split.json")))
    coincident = {"mesh": {"positions": [0, 0, 0, 0, 0, 0, 1, 1, 0], "uvs": [0, 0, 1, 0, 1, 1], "indices": [0, 1, 2]},
                  "include": FRAMES}
    sliver = {"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1e-16, 0], "uvs": [0, 0, 1, 0, 0, 1, 1, 0.5],
                       "indices": [0, 1, 2, 1, 3, 2]}, "include": FRAMES}
    zero_normals = {"mesh": {**QUAD, "normals": [0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1]}, "include": FRAMES + ["stats"]}
    zero_at = [v for v in range(4) if not any(zero_normals["mesh"]["normals"][3 * v:3 * v + 3])]
    out = [
        ("fog", "DISTANCE_EXP2, d_c = 1e-9 over [0, 1e6]", "fog",
         fog({"fogType": "DISTANCE_EXP2", "distanceCoefficient": 1e-9}, table={"size": 64, "range": [0, 1e6]}),
         fog_table(lambda d: math.exp(-1e-9 * d * d)), "every entry = exp(−d_c·d²) within 2e-6 (float32)"),
        ("fog", "DISTANCE_EXP2, d_c = 1e6", "fog",
         fog({"fogType": "DISTANCE_EXP2", "distanceCoefficient": 1e6}, table={"size": 64, "range": [0, 16]}),
         fog_table(lambda d: math.exp(-1e6 * d * d) if d < 1 else 0.0), "1 at d = 0, exactly 0 after (underflow, not NaN)"),
        fog_points("EXPONENTIAL (X3D) at d = 1e300", {"fogType": "EXPONENTIAL", "visibilityRange": 10}, [[0, 0, -1e300]],
                   "f = 0 exactly (d ≥ V)"),
        ("fog", "LINEAR (X3D), visibilityRange 1e300", "fog",
         fog({"fogType": "LINEAR", "visibilityRange": 1e300}, table={"size": 32, "range": [0, 1e300]}),
         fog_table(lambda d: max(0.0, (1e300 - d) / 1e300)), "f = (V − d)/V at every entry: 1 down to 0"),
        ("fog", "GL_LINEAR, start 1e-300, end 2e-300", "fog",
         fog({"fogType": "GL_LINEAR", "start": 1e-300, "end": 2e-300}, table={"size": 16, "range": [0, 4e-300]}),
         fog_table(lambda d: min(1.0, max(0.0, (2e-300 - d) / 1e-300))), "clamp((end − d)/(end − start)) on a 1e-300 scale"),
        ("fog", "GL_LINEAR, start = end", "fog", fog({"fogType": "GL_LINEAR", "start": 5, "end": 5}),
         problem(400, "/fog/end"), "a 400 naming /fog/end (no division by 0)"),
        ("fog", "GL_EXP, density 1e-300 (default range)", "fog", fog({"fogType": "GL_EXP", "density": 1e-300}, table={"size": 16}),
         problem(422, "/table/range"), "f reaches 1/255 at 5.5e300, beyond what a request can send back: 422 asking for range"),
        ("fog", "ATMOSPHERIC, extinction 1e-300, 1, 300", "fog",
         fog({"fogType": "ATMOSPHERIC", "extinction": [1e-300, 1, 300], "inscattering": [0, 0, 0]},
             table={"size": 32, "range": [0, 10]}),
         fog_transmittance([1e-300, 1, 300]), "transmittance e^(−β·d) per channel: 1, e^−d, below 1e-40 from the second entry"),
        ("fog", "HEIGHT, falloff 0 (uniform density)", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 3, "layout": "linear"}),
         fog_table(lambda d, dy: math.exp(-0.05 * d)), "the b → 0 limit: Beer–Lambert, exp(−a·d) on every ray"),
        ("fog", "HEIGHT, falloff 100", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 100, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 3, "layout": "linear"}),
         fog_table(lambda d, dy: height_f(0.05, 100, 0, 3, dy, d)),
         "the closed form: rays that stay up see almost no fog, rays that dive into the 1 cm layer are fogged"),
        ("fog", "HEIGHT, falloff 1e300 (a layer of zero thickness)", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 1e300, "baseHeight": 0},
             table={"size": 16, "elevations": 9, "cameraHeight": 3, "range": [0, 100], "layout": "linear"}),
         fog_table(lambda d, dy: height_f(0.05, 1e300, 0, 3, dy, d)),
         "e^(−b·Δh) at b = 1e300: no fog on level and rising rays, all fog below the layer; no 0·∞"),
        ("fog", "HEIGHT, density 1e300", "fog",
         fog({"fogType": "HEIGHT", "density": 1e300, "heightFalloff": 0.2, "baseHeight": 0},
             table={"size": 16, "elevations": 9, "cameraHeight": 3, "range": [0, 100], "layout": "linear"}),
         fog_table(lambda d, dy: height_f(1e300, 0.2, 0, 3, dy, d)), "f = 0 for any d > 0, 1 at the camera"),
        ("fog", "GL_EXP2, density 1e150 (its square overflows)", "fog",
         fog({"fogType": "GL_EXP2", "density": 1e150}, table={"size": 16, "range": [0, 1]}),
         fog_table(lambda d: 1.0 if d == 0 else 0.0), "(density·d)² = ∞ past d = 0: f = 0 exactly, not NaN"),
        ("fog", "HEIGHT, camera 1e6 above the layer", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 1e6, "layout": "linear"}),
         problem(422, "/table/range"), "most rays never reach 1/255: a 422 asking for an explicit range"),
        ("fog", "HEIGHT, camera 1e6 above the layer, range [0, 1e7]", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 1e6, "range": [0, 1e7], "layout": "linear"}),
         fog_table(lambda d, dy: height_f(0.05, 0.2, 0, 1e6, dy, d)), "the closed form with e^(−b·h) underflowing: f = 1 up high"),
        fog_points("HEIGHT, horizontal rays inside the layer", HEIGHT, [[1e3, 0, 0], [1e6, 0, 0], [0, 0, -50]],
                   "b·Δh → 0: exp(−a·d) at the camera's density (e^−50, 0, e^−2.5)"),
    ] + fog_sample_rows() + warped_rows() + unreal_rows() + [
        ("lightning", "η = 0 (uniform growth), 64², fast, dbm and charges", "lightning", uniform,
         bolts_equal(uniform, "the same bolt from fast, dbm and charges"),
         "η = 0 weighs every candidate alike whatever the field (0⁰ = 1, even where Φ underflows): the three methods "
         "grow the same bolt, cell for cell, a connected tree inside the grid that reaches the target"),
        ("lightning", "η = 50, 64², fast and dbm", "lightning", [bolt(64, eta=50), bolt(64, eta=50, method="dbm")],
         lambda answers: (ok_status(200, answers) and all(len(cells_of(a)) <= 70 and not tree_problems(bolt(64), a, cells_of(a))
                                                          for _, a in answers),
                          "cells " + ", ".join(str(len(cells_of(a))) for _, a in answers) + " (64 is the straight line)"),
         "weights in log space: an almost straight bolt (≤ 70 cells, a tree rooted at the start) from both methods",
         mutation("a 10-cell side branch on the fast bolt (η weakened)", side_branch)),
        ("lightning", "3 × 3 grid, start next to the target", "lightning",
         {"grid": {"width": 3, "height": 3}, "start": [1, 0], "targets": [[1, 1]], "include": ["cells"]},
         lambda answers: (answers[0][0] == 200 and answers[0][1]["cells"] == [1, 0, 1, 1], f"cells {answers[0][1].get('cells')}"),
         "the bolt is exactly the two cells",
         mutation("the second cell one step diagonal of the target", lambda answers: answers[0][1]["cells"].__setitem__(2, 0))),
        ("lightning", f"{1024 if quick else 4096}², fast", "lightning", bolt(1024 if quick else 4096), None,
         "a connected tree that reaches the target"),
        ("lightning", "walled-in target", "lightning", walled(32), problem(422, "/targets/0"),
         "A* proves it unreachable first: a 422 naming the target"),
        ("lightning", "one-cell corridor, dbm", "lightning", corridor(48),
         lambda answers: (answers[0][0] == 200 and cells_of(answers[0][1]) == [(24, y) for y in range(48)]
                          and not tree_problems(corridor(48), answers[0][1], cells_of(answers[0][1])),
                          f"{len(cells_of(answers[0][1]))} cells"),
         "the bolt is the corridor, cell for cell: x = 24, y = 0 … 47 in order, a tree",
         mutation("the last cell missing (a bolt one short)", lambda answers: answers[0][1]["cells"].__delitem__(slice(-2, None)))),
        ("lightning", "dbm at tolerance 1e-12 (its limit), 48²", "lightning", bolt(48, method="dbm", solver="mgpcg", tolerance=1e-12),
         bolt_ok(bolt(48, method="dbm", solver="mgpcg", tolerance=1e-12),
                 lambda a: (a["stats"]["counters"]["residual"] <= 1e-12, f"residual {a['stats']['counters']['residual']:.2g}")),
         "the relative residual reached ≤ 1e-12; a connected tree to the target",
         mutation("the residual ×100 (a solve stopped early)",
                  lambda answers: answers[0][1]["stats"]["counters"].update(residual=100 * answers[0][1]["stats"]["counters"]["residual"]))),
        ("lightning", "dbm at tolerance 0.1 (its limit), 48²", "lightning", bolt(48, method="dbm", solver="mgpcg", tolerance=0.1),
         None, "a loose solve still grows a connected tree to the target"),
        ("lightning", "charges, 64², η 2", "lightning", charges_pair,
         bolts_equal(charges_pair, f"the paper variant's bolt at η = {charges_power:.4f}"),
         f"a connected tree, the same cell for cell as the paper variant's (power = η) at η = 5.2·2^0.7·(64/128)^0.2 = "
         f"{charges_power:.4f} with the same seed: the calibration's power law ran",
         regrown(bolt(64, method="charges", variant="paper"), "the bolt at power η = 2 (the calibration not applied)")),
        ("lightning", "3-D, fast, 64³", "lightning",
         {"grid": {"width": 64, "height": 64, "depth": 64}, "start": [32, 0, 32], "targets": [[32, 63, 32]],
          "include": ["cells", "tree", "stats"]}, None, "a connected 26-neighbour tree that reaches the target"),
    ]
    for i, c in enumerate(out):
        if c[4] is None:
            out[i] = c[:4] + (bolt_ok(c[3]),) + c[5:]
    for width in (3, 5, 7, 9):
        runs = [(64, s) for s in range(1, 5)] + [(channel_long, s) for s in range(1, seeds_long + 1)]
        out.append(("lightning", f"dbm in a {width}-wide channel, length 64 and {channel_long}", "lightning",
                    [channel(width, L, s) for L, s in runs], per_row(runs, filled=0.5 * width),
                    "cells per row independent of the length (±12 %), the channel not filled: the field ahead of "
                    "the bolt (down to 1e-" + str(int(math.pi * channel_long / (width + 1) / math.log(10))) +
                    ") resolved by DeepField"))
    eden = [(length, eta, s) for length in (64, 600) for eta in (0, 1e-6) for s in (1, 2, 3)]
    out.append(("lightning", "dbm at η = 1e-6 against η = 0 in a 3-wide channel, length 64 and 600", "lightning",
                [channel(3, L, s, eta=eta) for L, eta, s in eden], same_fill(eden),
                "η → 0 is uniform growth: the same cells per row as η 0 (±5 %), every candidate weighed, even "
                "where its potential underflows"))
    tube_runs = [(48, s) for s in range(1, 5)] + [(240 if quick else 960, s) for s in range(1, 3)]
    out.append(("lightning", f"3-D dbm in a 3 × 3 tube, length 48 and {tube_runs[-1][0]}", "lightning",
                [tube(L, s) for L, s in tube_runs], per_row(tube_runs, filled=3.0),
                "voxels per unit length independent of the length (±12 %), under 3 of the tube's 9 per slice"))
    bub = {"time": 1, "camera": [0, 0, 3], "params": {"n1": 1.5, "n2": 1.0, "wobbleAmplitude": 0.05},
           "mesh": {"level": 3, "radius": 1}, "include": ["mesh"]}
    wob = {"time": 7, "camera": [0, 0, 3], "params": {"wobbleAmplitude": 0.1, "wobbleFrequency": 5},
           "mesh": {"level": 2, "radius": 1}, "include": ["mesh"]}
    out += [
        ("bubble", "grazing view, TIR (n₁ 1.5 outside, n₂ 1.0)", "bubble", bub, final_vectors(bub),
         "eqn 8 past the critical angle (T = 0): every vertex's final vector equals R·μ_top + T computed here from its "
         "position and normal (within 1e-5), finite at the silhouette"),
        ("bubble", "film thickness 0 … 1e4 nm; n₂ = 1", "bubble",
         [{"features": {"iridescence": True}, "thinFilm": {"thicknessRange": [0, 10000], "width": 64, "height": 16},
           "include": ["thinFilm"]},
          {"features": {"iridescence": True}, "params": {"n2": 1}, "thinFilm": {"width": 16, "height": 16}, "include": ["thinFilm"]}],
         thin_film_zero_and_air, "thickness 0 reflects nothing (1 only at grazing); a film of air's index reflects nothing",
         mutation("thickness 0 reflecting 1 % off grazing", zero_film_reflects)),
        ("bubble", "n₂ = 1 + 1e-6: a film barely denser than air", "bubble",
         {"features": {"iridescence": True}, "params": {"n2": 1 + 1e-6}, "thinFilm": {"width": 16, "height": 16},
          "include": ["thinFilm"]}, faint_film(1 + 1e-6),
         "each row at most the two interfaces' Fresnel bound (|r₁₂| + |r₂₃|)² ≈ 4r² (×1.5 for sRGB's out-of-gamut "
         "reach): 1e-12 at normal incidence, more towards grazing; no colour, no 0/0"),
        ("bubble", "t = 1e9 s", "bubble",
         [{"time": t, "camera": [0, 0, 3], "params": {"wobbleAmplitude": 0.05}, "mesh": {"level": 2, "radius": 1},
           "include": ["mesh"]} for t in (1e9, math.fmod(1e9, math.pi))],
         lambda answers: (ok_status(200, answers) and worst(answers[0][1]["mesh"]["positions"], answers[1][1]["mesh"]["positions"]) <= 1e-5,
                          f"max |p(1e9) − p(1e9 mod π)| {worst(answers[0][1]['mesh']['positions'], answers[1][1]['mesh']['positions']):.2g}"),
         "the wobble's phase δ·t reduced mod 2π in double: the mesh at 1e9 s equals the mesh at 1e9 mod π s (δ = 2)",
         mutation("one vertex at 1e9 s nudged by 1e-4", lambda answers: answers[0][1]["mesh"]["positions"].__setitem__(
             0, answers[0][1]["mesh"]["positions"][0] + 1e-4))),
        ("bubble", "wobble at its bound (amplitude × frequency 0.5), t = 7", "bubble", wob, checked_by_sweep(wob),
         "dented, never folded: no triangle inverted or degenerate"),
        ("bubble", "the paper's literal wobble (amplitude 1, frequency 1)", "bubble",
         {"time": 7, "params": {"wobbleVariant": "paper", "wobbleAmplitude": 1}, "include": ["mesh"]},
         problem(422, "/params/wobbleAmplitude"), "its Jacobian reaches 0: a 422 naming the field"),
        ("bubble", "radius 1e-6 under the paper's wobble of 0.05", "bubble",
         {"time": 1, "params": {"wobbleVariant": "paper", "wobbleAmplitude": 0.05}, "mesh": {"level": 2, "radius": 1e-6},
          "include": ["mesh"]},
         problem(422, "/mesh/radius"), "float32 cannot hold the shape: a 422 naming the radius, not a collapsed mesh"),
        ("bubble", "radius 1e-6 and 1e6, relative wobble", "bubble",
         [{"time": 7, "mesh": {"level": 2, "radius": r}, "include": ["mesh"]} for r in (1e-6, 1e6)],
         bubble_scale_invariant([1e-6, 1e6]), "the same shape at every size (positions / radius equal within 1e-5)"),
        ("bubble", "film swirl 10, swirl speed 1e6, t = 1e12", "bubble",
         {"time": 1e12, "film": {"swirl": 10, "swirlSpeed": 1e6, "width": 32, "height": 16}, "include": ["thickness"]},
         drained_film(300),
         "drained (α = 1 past 20 s): every texel within the profile's [0, H] = [0, 300] nm, its bottom near 300"),
        ("tangents", "zero-area triangles and zero-area UVs", "tangents", degenerate,
         unit_frames(degenerate, lambda a: (
             [a["stats"]["counters"].get(k) for k in ("degenerateTriangles", "zeroUvAreaTriangles")] == list(bad_triangles(degenerate)),
             f"{a['stats']['counters'].get('degenerateTriangles', 0):g} triangles with coincident corners and "
             f"{a['stats']['counters'].get('zeroUvAreaTriangles', 0):g} of zero UV area counted")),
         "unit frames ⟂ normals everywhere, the fallback frame where no triangle gives one; the counters equal the "
         f"script's count: {bad_triangles(degenerate)[0]} triangles with coincident corners, {bad_triangles(degenerate)[1]} "
         "with zero UV area"),
        ("tangents", "mirrored UVs", "tangents", mirrored,
         unit_frames(mirrored, lambda a: ({-1.0, 1.0} <= set(a["tangents"][3::4]), f"handedness {sorted(set(a['tangents'][3::4]))}")),
         "both handednesses present: each corner's w the sign of its triangle's UV area, its tangent along ∂p/∂u"),
        ("tangents", "coincident corners", "tangents", coincident, unit_frames(coincident),
         "no area: the fallback frame ((1, 0, 0) in the normal's plane, w = −1), unit and finite"),
        ("tangents", "a triangle of area 1e-16 beside a healthy one", "tangents", sliver, unit_frames(sliver),
         "the sliver's frame is unit, finite, orthogonal to its normal and along its ∂p/∂u"),
        ("tangents", "zero-length given normals", "tangents", zero_normals,
         unit_frames(zero_normals, lambda a: (
             a["stats"]["counters"].get("replacedNormals") == len(zero_at)
             and all(a["normals"][3 * v:3 * v + 3] == [0, 0, 1] for v in zero_at),
             f"replacedNormals {a['stats']['counters'].get('replacedNormals')}, normals "
             + ", ".join(str(a["normals"][3 * v:3 * v + 3]) for v in zero_at))),
         f"the {len(zero_at)} zero normals (vertices {', '.join(map(str, zero_at))}) replaced by +z and counted; frames along ∂p/∂u"),
        ("tangents", "coordinates at 1e-30, 1e6 and 1e38 scale", "tangents",
         [{"mesh": scaled(QUAD, k), "include": FRAMES} for k in (1, 1e-30, 1e6, 1e38)],
         tangents_equal_at_scales({"mesh": QUAD}, [1e-30, 1e6, 1e38]),
         "tangents are directions: the same as at scale 1 within 1e-6, along ∂p/∂u at every scale"),
    ]
    return out + scene_rows() + render_rows() + glow_rows()


# ---- the glow through fog: the APSF (docs/effects.md §5) -----------------------------------------
def apsf_py(t, q, mu):
    """The series written out again here (log-space terms, Legendre recurrence), per steradian over
    4 pi T^-2: the server's code is not used. T below 1.05 takes 1.05's shape (glow.h)."""
    t = min(max(t, 1.05), 1e4)
    total, lp, lc, m = 0.0, 1.0, mu, 1
    while True:
        beta = 0.0 if m == 1 else (2 * m + 1) / m * (1 - q ** (m - 1))
        r = math.exp(-beta * t - (m - 1) * math.log(t))
        total += r * (lp + lc)
        if m > 3 and r < 1e-18 and (m - 1) * math.log(t) > 40:
            break
        lp, lc = lc, ((2 * m + 1) * mu * lc - m * lp) / (m + 1)
        m += 1
    return max(total, 0.0) / (4 * math.pi)


def glow_body(glow, fog_def=None):
    return {"fog": fog_def or {"fogType": "GL_EXP", "density": 0.01}, "glow": glow, "include": ["glow"]}


def glow_table(expected, must_direct=None, tol=2e-7):
    """Every table entry against expected(theta) within tol relative (the answer's numbers are
    floats: 6e-8) or 1e-9 absolute (the entries that should be 0), and direct = must_direct when given."""
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        g = a["glow"]
        t = g["table"]
        exp = [expected(math.radians(x)) for x in t["angleDeg"]]
        got = t["perSteradian"]
        err = max((abs(o - e) / e for o, e in zip(got, exp) if e > 1e-9), default=0.0)
        ok = len(got) == len(exp) and all(math.isfinite(o) and (abs(o - e) <= 1e-9 or abs(o - e) <= tol * e)
                                          for o, e in zip(got, exp))
        if must_direct is not None:
            ok = ok and all(abs(o - e) <= 1e-12 + tol * e for o, e in ((g["direct"], must_direct), (g["scattered"], 1 - must_direct)))
        return ok, (f"{len(got)} entries, K(0) = {got[0]:.6g}; max relative |K − closed form| {err:.2g} (above 1e-9); "
                    f"direct {g['direct']:.3g}, scattered {g['scattered']:.3g} (T {g['opticalThickness']:.4g})")
    def change(answers):
        answers[0][1]["glow"]["table"]["perSteradian"][0] *= 1.001
    return with_mutation(check, "K(0) ×1.001", change)


def glow_invariant(answers):
    """The glow of a fog's ray equals the glow of its optical thickness given: T = density × length."""
    (s1, a1), (s2, a2) = answers
    if s1 != 200 or s2 != 200:
        return False, f"status {s1}, {s2}"
    g1, g2 = a1["glow"], a2["glow"]
    ok = abs(g1["opticalThickness"] - 2) <= 1e-9 and g1["table"] == g2["table"] and g1["gaussians"] == g2["gaussians"]
    return ok, f"T from the fog {g1['opticalThickness']:.12g} (2 given); tables and Gaussians equal: {g1['table'] == g2['table']}"


def halo_grows(answers):
    radii = [a["glow"]["haloRadiusDeg"] for s, a in answers if s == 200]
    ok = len(radii) == len(answers) and all(b > a for a, b in zip(radii, radii[1:]))
    return ok, "halo radius " + ", ".join(f"{r:.3g}°" for r in radii)


def glow_rows():
    table = {"kernel": "table", "samples": 19, "maxAngleDeg": 180}
    def closed_q1(t):
        def k(theta):
            x = 1 / t
            g = 1 / math.sqrt(1 - 2 * math.cos(theta) * x + x * x)
            return (g / t ** 2 + (g - 1) / t) * t * t / (4 * math.pi)
        return k
    diffuse = lambda theta: (1 + math.cos(theta)) / (4 * math.pi)
    return [
        ("glow", "APSF, q = 1 (all forward), T = 1.3", "fog", glow_body({**table, "opticalThickness": 1.3, "forwardScattering": 1}),
         glow_table(closed_q1(1.3), math.exp(-1.3)),
         "β_m = 0: the Legendre generating function, K = (G/T² + (G − 1)/T)·T²/4π, G = (1 − 2μ/T + 1/T²)^−½, within 2e-7 (the answer's floats); direct e^−T"),
        ("glow", "APSF, T = 1e300 (every g_m past g_1 underflows)", "fog", glow_body({**table, "opticalThickness": 1e300, "forwardScattering": 0.9}),
         glow_table(diffuse, 0.0),
         "the diffuse limit (1 + μ)/4π in log space, finite; direct 0, scattered 1"),
        ("glow", "APSF, T = 0 (clear air)", "fog", glow_body({**table, "opticalThickness": 0, "forwardScattering": 0.9}),
         glow_table(lambda th: apsf_py(0, 0.9, math.cos(th)), 1.0),
         "nothing scattered (direct 1, scattered 0: the halo gone); the shape at the series' floor T = 1.05, as the series summed here"),
        ("glow", "APSF, q = 0 (isotropic), T = 3 (0⁰ at m = 1)", "fog", glow_body({**table, "opticalThickness": 3, "forwardScattering": 0}),
         glow_table(lambda th: apsf_py(3, 0.0, math.cos(th)), math.exp(-3)),
         "the series summed here in Python (β_1 = 0 for every q) within 2e-7 relative"),
        ("glow", "fog GL_EXP density 1e300 between camera and light 1 apart", "fog",
         glow_body({**table, "camera": [0, 0, 0], "source": [0, 0, -1]}, {"fogType": "GL_EXP", "density": 1e300}),
         glow_table(diffuse, 0.0),
         "T = −ln 0 held at 745 (e^−745, the last double): finite, the diffuse shape, direct 0"),
        ("glow", "T from the fog = T given (GL_EXP 0.01 over 200)", "fog",
         [glow_body({"camera": [0, 0, 0], "source": [0, 0, -200], "forwardScattering": 0.9}),
          glow_body({"opticalThickness": 2, "forwardScattering": 0.9})],
         with_mutation(glow_invariant, "T from the fog 1 % off",
                       lambda answers: answers[0][1]["glow"].__setitem__("opticalThickness", 2.02)),
         "an invariance: the ray's T = density·length = 2, and the same kernel as T = 2 given"),
        ("glow", "halo radius against T (q 0.95): 1.2, 2, 4, 8, 40", "fog",
         [glow_body({"opticalThickness": t, "forwardScattering": 0.95, "kernel": "table", "samples": 256}) for t in (1.2, 2, 4, 8, 40)],
         with_mutation(halo_grows, "T 2's radius past T 4's",
                       lambda answers: answers[1][1]["glow"].__setitem__("haloRadiusDeg", answers[2][1]["glow"]["haloRadiusDeg"] + 1)),
         "the half-light radius grows strictly with T (the issue's monotone halo)"),
        ("glow", "neither T nor a ray", "fog", glow_body({"kernel": "gaussian"}), problem(400, "/glow"),
         "a 400 naming /glow"),
    ]


SERVER = None


DEFAULT_MUTATIONS = {"lightning": mutation(CELL_OFF, cell_off),
                     "tangents": mutation("the first frame flipped (t → −t)", flip_frame)}


def try_mutation(check, answers, mutated):
    """(column text, caught): the row's mutation fed to its own check, which must reject it."""
    if mutated is None:
        return "none", False
    text, fn = mutated
    try:
        wrong = fn(answers)
    except Exception as e:  # noqa: BLE001  (a mutation that cannot be made proves nothing)
        return f"{text} (could not be made: {e!r})", False
    try:
        ok, _ = check(wrong)
    except Exception:  # noqa: BLE001  (a check that cannot read the wrong answer rejects it)
        ok = False
    return text, not ok


def run_cases(server, quick, mutations=False):
    global SERVER
    SERVER = server
    rows = []
    for row in cases(quick):
        effect, name, endpoint, bodies, check, must = row[:6]
        mutated = row[6] if len(row) > 6 else getattr(check, "mutation", None) or DEFAULT_MUTATIONS.get(effect)
        bodies = bodies if isinstance(bodies, list) else [bodies]
        endpoints = endpoint if isinstance(endpoint, list) else [endpoint] * len(bodies)  # a list: one per body
        answers, ms = [], []
        for e, b in zip(endpoints, bodies):
            status, answer, seconds = server.post("/v1/" + e, b)
            answers.append((status, answer if isinstance(answer, (dict, bytes)) else {}))  # bytes: a PNG
            ms.append(seconds * 1000)
        try:
            ok, seen = check(answers)
        except Exception as e:  # noqa: BLE001  (a check that cannot read the answer fails its row)
            ok, seen = False, f"check could not read the answer: {e!r}"
        if mutations and not ok:
            caught = True  # the row fails the run already; its answers are no base for a mutation
            mut = f"{mutated[0] if mutated else 'none'}: not tried (the check failed)"
        elif mutations:
            text, caught = try_mutation(check, answers, mutated)
            mut = f"{text}: {'caught' if caught else 'NOT caught'}"
        else:
            mut = f"{mutated[0] if mutated else 'none'} (not run: --mutations)"
        method = answers[0][1].get("method", "") if answers[0][0] == 200 and isinstance(answers[0][1], dict) else ""
        msq = sorted(ms)[len(ms) // 2]
        rows.append((effect, name, "/".join(sorted({str(s) for s, _ in answers})), method, f"{msq:.1f}", must, seen,
                     mut, "✓" if ok else "✗ FAILED"))
        print(f"{'ok  ' if ok else 'FAIL'} {effect}: {name}: {seen}"
              + (f" [mutation {'caught' if caught else 'NOT CAUGHT'}]" if mutations else ""), flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--quick", action="store_true", help="smaller sizes of the heavy cases")
    ap.add_argument("--check", action="store_true", help="exit 1 when a check fails (or, with --mutations, misses its mutation)")
    ap.add_argument("--mutations", action="store_true", help="feed each row's mutation (a plausible wrong answer) to its check")
    ap.add_argument("--no-sweep", action="store_true")
    ap.add_argument("--sweep-requests", type=int, default=3000)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "stability.md"))
    ap.add_argument("--command", default=None, help="the command named in the stamp (scripts/report.sh passes its own)")
    args = ap.parse_args()
    server = Server(args.binary, 600)
    try:
        rows = run_cases(server, args.quick, args.mutations)
    finally:
        server.stop()
    failed = [r for r in rows if not r[-1].startswith("✓")]
    missed = [r for r in rows if r[7].endswith("NOT caught")] if args.mutations else []
    caught = sum(r[7].endswith(": caught") for r in rows)
    untried = sum(r[7].endswith("not tried (the check failed)") for r in rows)
    command = ("scripts/stability-report.py build/server/effectd" + (" --quick" if args.quick else "")
               + (" --mutations" if args.mutations else ""))
    md = ["# Numerical stability: stiff and extreme cases, checked",
          "",
          stamp(args.command or command, "stability.md"),
          "",
          "Each row is one or more requests to the running server and a check that can fail: a closed form "
          "computed by the script (docs/effects.md's formulas, not the server's code), an invariance between "
          "requests (the same answer at another scale, length or size), or the exact 4xx it must get. "
          "A row is right only when its check passes (✓); `--check` makes a failed row fail the run, and the test "
          "suite runs the quick sizes that way (`stability_checks` in ctest). ms: the median request's "
          "wall-clock time from the client. Fog factors, transmittances and colours are compared within 2e-6 and, "
          "above 1e-30, within 1e-5 relative (so that e^−50 1 % off fails); a bolt's \"connected tree\" is checked "
          "cell by cell: rooted at the start, every parent grown before its child and a grid neighbour of it, no cell "
          "twice, the main channel the parent chain from the start to the target. Render rows decode the PNGs here "
          "(zlib) and compare the preview with the CPU reference over the sphere's closed-form silhouette. "
          "mutation: a plausible wrong answer made from the real ones and fed to "
          "the same check (`--mutations`), which must reject it (caught); with `--check` one it lets through fails "
          "the run too.",
          "",
          f"**{len(rows) - len(failed)} of {len(rows)} checks pass"
          + (f"; {caught} of {len(rows)} mutations caught" + (f" ({untried} not tried: their rows fail)" if untried else "")
             if args.mutations else "") + ".**",
          "",
          "| effect | case | status | method | ms | must hold | seen | mutation | check |",
          "|---|---|---|---|---|---|---|---|---|"]
    for r in rows:
        md.append("| " + " | ".join(x.replace("|", "\\|") for x in r) + " |")
    if not args.no_sweep:
        with tempfile.TemporaryDirectory() as tmp:
            out = os.path.join(tmp, "sweep.json")
            subprocess.run([sys.executable, os.path.join(ROOT, "tests", "sweep_test.py"), args.binary,
                            "--requests", str(args.sweep_requests), "--seed", "1", "--json", out], check=False)
            sweep = json.load(open(out))
        c = sweep["counts"]
        md += ["",
               "## The property sweep",
               "",
               f"`tests/sweep_test.py build/server/effectd --requests {args.sweep_requests} --seed 1` (the test suite "
               "runs 800 requests in Release, 150 under ASan+UBSan): requests drawn from the full ranges the request "
               "schemas allow, checked against invariants (tests/sweep_test.py's docstring lists them).",
               "",
               f"- requests: {c['requests']} (regressions replayed first: {c['regressions']}); per endpoint: "
               + ", ".join(f"{k} {v}" for k, v in sorted(c["byEndpoint"].items())),
               "- statuses: " + ", ".join(f"{k}: {v}" for k, v in sorted(c["byStatus"].items())),
               f"- invariants checked: {c['invariantsChecked']}; **violations: {c['violations']}**",
               f"- slowest request: {c['slowest'][0]} s ({c['slowest'][1]})"]
        for f in sweep["failures"]:
            md.append(f"- VIOLATION: `{json.dumps(f)[:400]}`")
            failed.append(f)
    with open(args.out, "w") as o:
        o.write("\n".join(md) + "\n")
    print(f"wrote {args.out}: {len(rows)} checks, {len(failed)} failed"
          + (f"; {caught} mutations caught, {len(missed)} not, {untried} not tried (their rows failed)" if args.mutations else ""))
    for r in missed:
        print(f"mutation NOT caught: {r[0]}: {r[1]}: {r[7]}")
    if args.check and (failed or missed):
        sys.exit(1)


if __name__ == "__main__":
    main()
