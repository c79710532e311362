#!/usr/bin/env python3
"""The stability report as checks: every effect's stiff and extreme cases sent to a running
effectd, each with a check that can fail (a closed form computed here, an invariance between
requests, or the exact 4xx it must get), and docs/stability.md written from what they saw.
A row is "right" only when its check passes; --check exits 1 when one does not.

    scripts/stability-report.py build/server/effectd [--quick] [--check] [--no-sweep]
                                [--sweep-requests N] [--out docs/stability.md]

--quick runs the smaller sizes of the heavy cases (the test suite runs it with --check);
the report (scripts/report.sh) runs the full sizes and the property sweep.
"""
import argparse
import datetime
import json
import math
import os
import subprocess
import sys
import tempfile
import time

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..")
sys.path.insert(0, os.path.join(ROOT, "tests"))
from sweep_test import Server, check_bubble, check_tangents  # noqa: E402
from report_stamp import stamp  # noqa: E402  (scripts/report_stamp.py)

QUAD = {"positions": [0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0], "uvs": [0, 0, 1, 0, 1, 1, 0, 1], "indices": [0, 1, 2, 0, 2, 3]}


# ---- closed forms (docs/effects.md section 2), computed here, not read from the server ---------
def height_f(a, b, h, oy, dy, t):
    """exp(-tau), tau = a e^(-b(oy-h)) t g(b dy t), g(x) = (1 - e^-x)/x, in log space."""
    if t == 0 or a == 0:
        return 1.0
    x = b * dy * t
    if abs(x) < 1e-12:
        lg = -x / 2
    elif x > 0:
        lg = math.log(-math.expm1(-x) / x)
    else:
        lg = -x + math.log(-math.expm1(x)) - math.log(-x)
    ltau = math.log(a * t) - b * (oy - h) + lg
    return 0.0 if ltau > 700 else math.exp(-math.exp(ltau))


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


# ---- checks: each takes the answers (one per request) and returns (ok, observed) ---------------
def ok_status(status, answers):
    return all(s == status for s, _ in answers)


def problem(status, pointer):
    def check(answers):
        s, a = answers[0]
        got = (a.get("errors") or [{}])[0].get("pointer") if isinstance(a, dict) else None
        return s == status and got == pointer, f"{s} at {got}: {(a.get('errors') or [{}])[0].get('message', '')}"
    return check


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
        err = worst(f, exp)
        return err <= tol, f"{len(f)} factors in [{min(f):.4g}, {max(f):.4g}]; max |f − closed form| {err:.2g}"
    return check


def fog_samples(expected):
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        f = [x["factor"] for x in a["samples"]]
        err = worst(f, expected)
        return err <= 2e-6, f"f = {', '.join(f'{x:.4g}' for x in f)}; max |f − closed form| {err:.2g}"
    return check


def fog_transmittance(coefficients):
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        t = a["table"]
        tr, ds = t["transmittance"], distances(t)
        exp = [math.exp(-min(700.0, c * d)) if c * d < 700 else 0.0 for d in ds for c in coefficients]
        err = worst(tr, exp)
        return err <= 2e-6, f"T per channel in [{min(tr):.4g}, {max(tr):.4g}]; max |T − e^(−β·d)| {err:.2g}"
    return check


def cells_of(a):
    c, dims = a["cells"], len(a["grid"])
    return [tuple(c[i:i + dims]) for i in range(0, len(c), dims)]


def tree_problems(body, a, cells):
    """Every cell inside the grid, none twice, each a neighbour of its parent (2-D or 3-D)."""
    grid, parent = a["grid"], a["tree"]["parent"]
    hood = body.get("neighbourhood", 26 if len(grid) == 3 else 8)
    problems = []
    if any(not all(0 <= c[k] < grid[k] for k in range(len(grid))) for c in cells):
        problems.append("a cell outside the grid")
    if len(set(cells)) != len(cells):
        problems.append("a cell twice")
    for i, q in enumerate(parent[1:], 1):
        d = [abs(cells[i][k] - cells[q][k]) for k in range(len(grid))]
        if max(d) != 1 or (hood in (4, 6) and sum(d) != 1):
            problems.append(f"cell {i} is not a neighbour of its parent")
            break
    return problems


def bolt_ok(body, pred=None):
    """Inside the grid, each cell next to its parent, the target reached; then pred(answer)."""
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
    return check


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
    return check


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
    return check


def tangents_equal_at_scales(scales):
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        ref = answers[0][1]["tangents"]
        err = max(worst(a["tangents"], ref) for _, a in answers[1:])
        probs = [p for _, a in answers for p in check_tangents({}, a, None)]
        return err <= 1e-6 and not probs, f"max |t(scale) − t(1)| {err:.2g} at scales {', '.join(f'{k:g}' for k in scales)}"
    return check


def unit_frames(pred=None):
    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        probs = check_tangents({}, a, None)
        seen = f"{len(a['tangents']) // 4} unit tangents ⟂ normals" if not probs else probs[0]
        if pred:
            ok2, s2 = pred(a)
            return not probs and ok2, seen + "; " + s2
        return not probs, seen
    return check


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
    return check


def bubble_scale_invariant(radii):
    def check(answers):
        if not ok_status(200, answers):
            return False, "statuses " + ", ".join(str(s) for s, _ in answers)
        shapes = [[v / r for v in a["mesh"]["positions"]] for r, (_, a) in zip(radii, answers)]
        err = max(worst(s, shapes[0]) for s in shapes[1:])
        return err <= 1e-5, f"max |p/r at radius {radii[1]:g} − p/r at {radii[0]:g}| = {err:.2g}"
    return check


def checked_by_sweep(answers_body):
    body = answers_body

    def check(answers):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        probs = check_bubble(body, a, SERVER)
        return not probs, "every triangle oriented as on the undisturbed sphere, none degenerate" if not probs else probs[0]
    return check


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


# (effect, case, endpoint, bodies, check, what must hold); bodies may be a list (invariances).
def cases(quick):
    channel_long = 512 if quick else 4096  # 3 x 65536 (the grid limit) would take about 25 min a bolt
    seeds_long = 1 if quick else 2
    out = [
        ("fog", "DISTANCE_EXP2, d_c = 1e-9 over [0, 1e6]", "fog",
         fog({"fogType": "DISTANCE_EXP2", "distanceCoefficient": 1e-9}, table={"size": 64, "range": [0, 1e6]}),
         fog_table(lambda d: math.exp(-1e-9 * d * d)), "every entry = exp(−d_c·d²) within 2e-6 (float32)"),
        ("fog", "DISTANCE_EXP2, d_c = 1e6", "fog",
         fog({"fogType": "DISTANCE_EXP2", "distanceCoefficient": 1e6}, table={"size": 64, "range": [0, 16]}),
         fog_table(lambda d: math.exp(-1e6 * d * d) if d < 1 else 0.0), "1 at d = 0, exactly 0 after (underflow, not NaN)"),
        ("fog", "EXPONENTIAL (X3D) at d = 1e300", "fog",
         fog({"fogType": "EXPONENTIAL", "visibilityRange": 10}, samples={"camera": [0, 0, 0], "points": [[0, 0, -1e300]]},
             include=["samples"]),
         fog_samples([0.0]), "f = 0 exactly (d ≥ V)"),
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
             table={"size": 64, "elevations": 16, "cameraHeight": 3}),
         fog_table(lambda d, dy: math.exp(-0.05 * d)), "the b → 0 limit: Beer–Lambert, exp(−a·d) on every ray"),
        ("fog", "HEIGHT, falloff 100", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 100, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 3}),
         fog_table(lambda d, dy: height_f(0.05, 100, 0, 3, dy, d)),
         "the closed form: rays that stay up see almost no fog, rays that dive into the 1 cm layer are fogged"),
        ("fog", "HEIGHT, falloff 1e300 (a layer of zero thickness)", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 1e300, "baseHeight": 0},
             table={"size": 16, "elevations": 9, "cameraHeight": 3, "range": [0, 100]}),
         fog_table(lambda d, dy: height_f(0.05, 1e300, 0, 3, dy, d)),
         "e^(−b·Δh) at b = 1e300: no fog on level and rising rays, all fog below the layer; no 0·∞"),
        ("fog", "HEIGHT, density 1e300", "fog",
         fog({"fogType": "HEIGHT", "density": 1e300, "heightFalloff": 0.2, "baseHeight": 0},
             table={"size": 16, "elevations": 9, "cameraHeight": 3, "range": [0, 100]}),
         fog_table(lambda d, dy: height_f(1e300, 0.2, 0, 3, dy, d)), "f = 0 for any d > 0, 1 at the camera"),
        ("fog", "GL_EXP2, density 1e150 (its square overflows)", "fog",
         fog({"fogType": "GL_EXP2", "density": 1e150}, table={"size": 16, "range": [0, 1]}),
         fog_table(lambda d: 1.0 if d == 0 else 0.0), "(density·d)² = ∞ past d = 0: f = 0 exactly, not NaN"),
        ("fog", "HEIGHT, camera 1e6 above the layer", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 1e6}),
         problem(422, "/table/range"), "most rays never reach 1/255: a 422 asking for an explicit range"),
        ("fog", "HEIGHT, camera 1e6 above the layer, range [0, 1e7]", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
             table={"size": 64, "elevations": 16, "cameraHeight": 1e6, "range": [0, 1e7]}),
         fog_table(lambda d, dy: height_f(0.05, 0.2, 0, 1e6, dy, d)), "the closed form with e^(−b·h) underflowing: f = 1 up high"),
        ("fog", "HEIGHT, horizontal rays inside the layer", "fog",
         fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
             samples={"camera": [0, 0, 0], "points": [[1e3, 0, 0], [1e6, 0, 0], [0, 0, -50]]}, include=["samples"]),
         fog_samples([math.exp(-50), 0.0, math.exp(-2.5)]), "b·Δh → 0: exp(−a·d) at the camera's density"),
        ("lightning", "η = 0 (uniform growth), 64²", "lightning", bolt(64, eta=0), None,
         "a connected tree inside the grid that reaches the target"),
        ("lightning", "η = 50, 64², fast and dbm", "lightning", [bolt(64, eta=50), bolt(64, eta=50, method="dbm")],
         lambda answers: (ok_status(200, answers) and all(len(cells_of(a)) <= 70 for _, a in answers),
                          "cells " + ", ".join(str(len(cells_of(a))) for _, a in answers) + " (64 is the straight line)"),
         "weights in log space: an almost straight bolt (≤ 70 cells) from both methods"),
        ("lightning", "3 × 3 grid, start next to the target", "lightning",
         {"grid": {"width": 3, "height": 3}, "start": [1, 0], "targets": [[1, 1]], "include": ["cells"]},
         lambda answers: (answers[0][0] == 200 and answers[0][1]["cells"] == [1, 0, 1, 1], f"cells {answers[0][1].get('cells')}"),
         "the bolt is exactly the two cells"),
        ("lightning", f"{1024 if quick else 4096}², fast", "lightning", bolt(1024 if quick else 4096), None,
         "a connected tree that reaches the target"),
        ("lightning", "walled-in target", "lightning", walled(32), problem(422, "/targets/0"),
         "A* proves it unreachable first: a 422 naming the target"),
        ("lightning", "one-cell corridor, dbm", "lightning", corridor(48),
         lambda answers: (answers[0][0] == 200 and len(cells_of(answers[0][1])) == 48,
                          f"{len(cells_of(answers[0][1]))} cells"), "the bolt is the corridor: 48 cells"),
        ("lightning", "dbm at tolerance 1e-12 (its limit), 48²", "lightning", bolt(48, method="dbm", solver="mgpcg", tolerance=1e-12),
         lambda answers: (answers[0][0] == 200 and answers[0][1]["stats"]["counters"]["residual"] <= 1e-12,
                          f"residual {answers[0][1]['stats']['counters']['residual']:.2g}"), "the relative residual reached ≤ 1e-12"),
        ("lightning", "dbm at tolerance 0.1 (its limit), 48²", "lightning", bolt(48, method="dbm", solver="mgpcg", tolerance=0.1),
         None, "a loose solve still grows a connected tree to the target"),
        ("lightning", "charges, 64², η 2", "lightning", bolt(64, method="charges"), None,
         f"a connected tree; the power that ran is 5.2·η^0.7·(64/128)^0.2 = {5.2 * 2 ** 0.7 * 0.5 ** 0.2:.4f}"),
        ("lightning", "3-D, fast, 64³", "lightning",
         {"grid": {"width": 64, "height": 64, "depth": 64}, "start": [32, 0, 32], "targets": [[32, 63, 32]],
          "include": ["cells", "tree", "stats"]}, None, "a connected 26-neighbour tree that reaches the target"),
    ]
    # The charges power is a closed form of η and the grid.
    for i, c in enumerate(out):
        if c[1] == "charges, 64², η 2":
            body = c[3]
            power = 5.2 * 2 ** 0.7 * (64 / 128) ** 0.2
            out[i] = c[:4] + (bolt_ok(body, lambda a: (abs(a["stats"]["counters"]["chargesEta"] - power) < 1e-9,
                                                       f"power {a['stats']['counters']['chargesEta']:.4f}")),) + c[5:]
        elif c[4] is None:
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
        ("bubble", "grazing view, TIR (n₁ 1.5 outside, n₂ 1.0)", "bubble", bub,
         lambda answers: (answers[0][0] == 200 and all(math.isfinite(v) for v in answers[0][1]["mesh"]["finalVectors"]),
                          f"{len(answers[0][1]['mesh']['finalVectors']) // 3} final vectors, all finite"),
         "eqn 8 past the critical angle (T = 0): finite at the silhouette"),
        ("bubble", "film thickness 0 … 1e4 nm; n₂ = 1", "bubble",
         [{"features": {"iridescence": True}, "thinFilm": {"thicknessRange": [0, 10000], "width": 64, "height": 16},
           "include": ["thinFilm"]},
          {"features": {"iridescence": True}, "params": {"n2": 1}, "thinFilm": {"width": 16, "height": 16}, "include": ["thinFilm"]}],
         thin_film_zero_and_air, "thickness 0 reflects nothing (1 only at grazing); a film of air's index reflects nothing"),
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
         "the wobble's phase δ·t reduced mod 2π in double: the mesh at 1e9 s equals the mesh at 1e9 mod π s (δ = 2)"),
        ("bubble", "wobble at its bound (amplitude × frequency 0.5), t = 7", "bubble", wob, checked_by_sweep(wob),
         "dented, never folded: no triangle inverted or degenerate"),
        ("bubble", "the paper's literal wobble (amplitude 1, frequency 1)", "bubble",
         {"time": 7, "params": {"wobbleVariant": "paper", "wobbleAmplitude": 1}, "include": ["mesh"]},
         lambda answers: (answers[0][0] == 422 and bool((answers[0][1].get("errors") or [{}])[0].get("pointer")),
                          f"{answers[0][0]} at {(answers[0][1].get('errors') or [{}])[0].get('pointer')}"),
         "its Jacobian reaches 0: a 422 naming the field"),
        ("bubble", "radius 1e-6 under the paper's wobble of 0.05", "bubble",
         {"time": 1, "params": {"wobbleVariant": "paper", "wobbleAmplitude": 0.05}, "mesh": {"level": 2, "radius": 1e-6},
          "include": ["mesh"]},
         lambda answers: (answers[0][0] == 422, f"{answers[0][0]}"), "float32 cannot hold the shape: a 422, not a collapsed mesh"),
        ("bubble", "radius 1e-6 and 1e6, relative wobble", "bubble",
         [{"time": 7, "mesh": {"level": 2, "radius": r}, "include": ["mesh"]} for r in (1e-6, 1e6)],
         bubble_scale_invariant([1e-6, 1e6]), "the same shape at every size (positions / radius equal within 1e-5)"),
        ("bubble", "film swirl 10, swirl speed 1e6, t = 1e12", "bubble",
         {"time": 1e12, "film": {"swirl": 10, "swirlSpeed": 1e6, "width": 32, "height": 16}, "include": ["thickness"]},
         lambda answers: (answers[0][0] == 200 and all(math.isfinite(v) and 0 < v <= 1000 for v in answers[0][1]["thickness"]["nm"]),
                          f"thickness in [{min(answers[0][1]['thickness']['nm']):.4g}, {max(answers[0][1]['thickness']['nm']):.4g}] nm"),
         "within the drainage profile's (0, 1000] nm"),
        ("tangents", "zero-area triangles and zero-area UVs", "tangents",
         {**json.load(open(os.path.join(ROOT, "proto/examples/tangents/04-degenerate-triangles.json"))),
          "include": ["tangents", "normals", "stats"]},
         unit_frames(lambda a: (a["stats"]["counters"].get("degenerateTriangles", 0) > 0,
                                f"{a['stats']['counters'].get('degenerateTriangles', 0):g} degenerate triangles counted")),
         "unit frames ⟂ normals everywhere, the degenerate triangles counted"),
        ("tangents", "mirrored UVs", "tangents", json.load(open(os.path.join(ROOT, "proto/examples/tangents/02-mirrored-uvs-split.json"))),
         unit_frames(lambda a: ({-1.0, 1.0} <= set(a["tangents"][3::4]), f"handedness {sorted(set(a['tangents'][3::4]))}")),
         "both handednesses present (−1 where mirrored)"),
        ("tangents", "coincident corners", "tangents",
         {"mesh": {"positions": [0, 0, 0, 0, 0, 0, 1, 1, 0], "uvs": [0, 0, 1, 0, 1, 1], "indices": [0, 1, 2]}},
         unit_frames(), "no area: the fallback frame, unit and finite"),
        ("tangents", "a triangle of area 1e-16 beside a healthy one", "tangents",
         {"mesh": {"positions": [0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1e-16, 0], "uvs": [0, 0, 1, 0, 0, 1, 1, 0.5],
                   "indices": [0, 1, 2, 1, 3, 2]}},
         unit_frames(), "the sliver's frame is unit, finite and orthogonal to its normal"),
        ("tangents", "zero-length given normals", "tangents",
         {"mesh": {**QUAD, "normals": [0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 0, 1]}, "include": ["tangents", "normals", "stats"]},
         unit_frames(lambda a: (a["stats"]["counters"].get("replacedNormals") == 2,
                                f"replacedNormals {a['stats']['counters'].get('replacedNormals')}")),
         "the two zero normals replaced by +z and counted"),
        ("tangents", "coordinates at 1e-30, 1e6 and 1e38 scale", "tangents",
         [{"mesh": scaled(QUAD, k)} for k in (1, 1e-30, 1e6, 1e38)], tangents_equal_at_scales([1e-30, 1e6, 1e38]),
         "tangents are directions: the same as at scale 1 within 1e-6"),
    ]
    return out


SERVER = None


def run_cases(server, quick):
    global SERVER
    SERVER = server
    rows = []
    for effect, name, endpoint, bodies, check, must in cases(quick):
        bodies = bodies if isinstance(bodies, list) else [bodies]
        answers, ms = [], []
        for b in bodies:
            status, answer, seconds = server.post("/v1/" + endpoint, b)
            answers.append((status, answer if isinstance(answer, dict) else {}))
            ms.append(seconds * 1000)
        try:
            ok, seen = check(answers)
        except Exception as e:  # noqa: BLE001  (a check that cannot read the answer fails its row)
            ok, seen = False, f"check could not read the answer: {e!r}"
        method = answers[0][1].get("method", "") if answers[0][0] == 200 else ""
        msq = sorted(ms)[len(ms) // 2]
        rows.append((effect, name, "/".join(sorted({str(s) for s, _ in answers})), method, f"{msq:.1f}", must, seen,
                     "✓" if ok else "✗ FAILED"))
        print(f"{'ok  ' if ok else 'FAIL'} {effect}: {name}: {seen}", flush=True)
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("--quick", action="store_true", help="smaller sizes of the heavy cases")
    ap.add_argument("--check", action="store_true", help="exit 1 when a check fails")
    ap.add_argument("--no-sweep", action="store_true")
    ap.add_argument("--sweep-requests", type=int, default=3000)
    ap.add_argument("--out", default=os.path.join(ROOT, "docs", "stability.md"))
    ap.add_argument("--command", default=None, help="the command named in the stamp (scripts/report.sh passes its own)")
    args = ap.parse_args()
    server = Server(args.binary, 600)
    try:
        rows = run_cases(server, args.quick)
    finally:
        server.stop()
    failed = [r for r in rows if not r[-1].startswith("✓")]
    md = ["# Numerical stability: stiff and extreme cases, checked",
          "",
          stamp(args.command or "scripts/stability-report.py build/server/effectd" + (" --quick" if args.quick else ""),
                "stability.md"),
          "",
          "Each row is one or more requests to the running server and a check that can fail: a closed form "
          "computed by the script (docs/effects.md's formulas, not the server's code), an invariance between "
          "requests (the same answer at another scale, length or size), or the exact 4xx it must get. "
          "A row is right only when its check passes (✓); `--check` makes a failed row fail the run, and the test "
          "suite runs the quick sizes that way (`stability_checks` in ctest). ms: the median request's "
          "wall-clock time from the client.",
          "",
          f"**{len(rows) - len(failed)} of {len(rows)} checks pass.**",
          "",
          "| effect | case | status | method | ms | must hold | seen | check |",
          "|---|---|---|---|---|---|---|---|"]
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
    print(f"wrote {args.out}: {len(rows)} checks, {len(failed)} failed")
    if args.check and failed:
        sys.exit(1)


if __name__ == "__main__":
    main()
