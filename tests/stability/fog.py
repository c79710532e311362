"""Fog's stiff and extreme cases: tables and `samples` against the closed forms of docs/effects.md §2
(every convention), warped HEIGHT tables against height_f at their own axes, and the exact 4xx.
Each row names its mutation: most take the farthest f in (0, 1) 1 % off (or a 0 read as 1, the
naive overflow)."""
import copy
import math

from stability.closed_forms import distances, exp_neg, fog_model, height_f, unreal_f, warped_row_y, warped_span
from stability.common import (HEIGHT, OFF_SAMPLES, OFF_TABLE, Mutation, case, fog, fog_points,
                              fog_table, frozen, message, near, off_values, parent_named, problem, rel_worst, worst)

UNREAL = frozen({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 1e-4, "baseHeight": 0, "convention": "unreal"})


def fog_transmittance(coefficients):
    """Every table entry's transmittance per channel against e^(−β·d) (mutation: OFF_TRANSMITTANCE)."""
    def check(answers, server):
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
    return check


OFF_TRANSMITTANCE = Mutation("the farthest T in (0, 1) ×0.99",
                             lambda answers, server: off_values(answers[0][1]["table"]["transmittance"]))


def table_rows():
    return [
        case("fog", "DISTANCE_EXP2, d_c = 1e-9 over [0, 1e6]", "fog",
             fog({"fogType": "DISTANCE_EXP2", "distanceCoefficient": 1e-9}, table={"size": 64, "range": [0, 1e6]}),
             check=fog_table(lambda d: math.exp(-1e-9 * d * d)), must="every entry = exp(−d_c·d²) within 2e-6 (float32)",
             mutation=OFF_TABLE),
        case("fog", "DISTANCE_EXP2, d_c = 1e6", "fog",
             fog({"fogType": "DISTANCE_EXP2", "distanceCoefficient": 1e6}, table={"size": 64, "range": [0, 16]}),
             check=fog_table(lambda d: math.exp(-1e6 * d * d) if d < 1 else 0.0),
             must="1 at d = 0, exactly 0 after (underflow, not NaN)", mutation=OFF_TABLE),
        fog_points("EXPONENTIAL (X3D) at d = 1e300", {"fogType": "EXPONENTIAL", "visibilityRange": 10}, [[0, 0, -1e300]],
                   "f = 0 exactly (d ≥ V)", mutation=OFF_SAMPLES),
        case("fog", "LINEAR (X3D), visibilityRange 1e300", "fog",
             fog({"fogType": "LINEAR", "visibilityRange": 1e300}, table={"size": 32, "range": [0, 1e300]}),
             check=fog_table(lambda d: max(0.0, (1e300 - d) / 1e300)), must="f = (V − d)/V at every entry: 1 down to 0",
             mutation=OFF_TABLE),
        case("fog", "GL_LINEAR, start 1e-300, end 2e-300", "fog",
             fog({"fogType": "GL_LINEAR", "start": 1e-300, "end": 2e-300}, table={"size": 16, "range": [0, 4e-300]}),
             check=fog_table(lambda d: min(1.0, max(0.0, (2e-300 - d) / 1e-300))),
             must="clamp((end − d)/(end − start)) on a 1e-300 scale", mutation=OFF_TABLE),
        case("fog", "GL_LINEAR, start = end", "fog", fog({"fogType": "GL_LINEAR", "start": 5, "end": 5}),
             check=problem(400, "/fog/end"), must="a 400 naming /fog/end (no division by 0)",
             mutation=parent_named(400, "/fog/end")),
        case("fog", "GL_EXP, density 1e-300 (default range)", "fog",
             fog({"fogType": "GL_EXP", "density": 1e-300}, table={"size": 16}),
             check=problem(422, "/table/range"),
             must="f reaches 1/255 at 5.5e300, beyond what a request can send back: 422 asking for range",
             mutation=parent_named(422, "/table/range")),
        case("fog", "ATMOSPHERIC, extinction 1e-300, 1, 300", "fog",
             fog({"fogType": "ATMOSPHERIC", "extinction": [1e-300, 1, 300], "inscattering": [0, 0, 0]},
                 table={"size": 32, "range": [0, 10]}),
             check=fog_transmittance([1e-300, 1, 300]),
             must="transmittance e^(−β·d) per channel: 1, e^−d, below 1e-40 from the second entry",
             mutation=OFF_TRANSMITTANCE),
        case("fog", "HEIGHT, falloff 0 (uniform density)", "fog",
             fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0, "baseHeight": 0},
                 table={"size": 64, "elevations": 16, "cameraHeight": 3, "layout": "linear"}),
             check=fog_table(lambda d, dy: math.exp(-0.05 * d)), must="the b → 0 limit: Beer–Lambert, exp(−a·d) on every ray",
             mutation=OFF_TABLE),
        case("fog", "HEIGHT, falloff 100", "fog",
             fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 100, "baseHeight": 0},
                 table={"size": 64, "elevations": 16, "cameraHeight": 3, "layout": "linear"}),
             check=fog_table(lambda d, dy: height_f(0.05, 100, 0, 3, dy, d)),
             must="the closed form: rays that stay up see almost no fog, rays that dive into the 1 cm layer are fogged",
             mutation=OFF_TABLE),
        case("fog", "HEIGHT, falloff 1e300 (a layer of zero thickness)", "fog",
             fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 1e300, "baseHeight": 0},
                 table={"size": 16, "elevations": 9, "cameraHeight": 3, "range": [0, 100], "layout": "linear"}),
             check=fog_table(lambda d, dy: height_f(0.05, 1e300, 0, 3, dy, d)),
             must="e^(−b·Δh) at b = 1e300: no fog on level and rising rays, all fog below the layer; no 0·∞",
             mutation=OFF_TABLE),
        case("fog", "HEIGHT, density 1e300", "fog",
             fog({"fogType": "HEIGHT", "density": 1e300, "heightFalloff": 0.2, "baseHeight": 0},
                 table={"size": 16, "elevations": 9, "cameraHeight": 3, "range": [0, 100], "layout": "linear"}),
             check=fog_table(lambda d, dy: height_f(1e300, 0.2, 0, 3, dy, d)), must="f = 0 for any d > 0, 1 at the camera",
             mutation=OFF_TABLE),
        case("fog", "GL_EXP2, density 1e150 (its square overflows)", "fog",
             fog({"fogType": "GL_EXP2", "density": 1e150}, table={"size": 16, "range": [0, 1]}),
             check=fog_table(lambda d: 1.0 if d == 0 else 0.0), must="(density·d)² = ∞ past d = 0: f = 0 exactly, not NaN",
             mutation=OFF_TABLE),
        case("fog", "HEIGHT, camera 1e6 above the layer", "fog",
             fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
                 table={"size": 64, "elevations": 16, "cameraHeight": 1e6, "layout": "linear"}),
             check=problem(422, "/table/range"), must="most rays never reach 1/255: a 422 asking for an explicit range",
             mutation=parent_named(422, "/table/range")),
        case("fog", "HEIGHT, camera 1e6 above the layer, range [0, 1e7]", "fog",
             fog({"fogType": "HEIGHT", "density": 0.05, "heightFalloff": 0.2, "baseHeight": 0},
                 table={"size": 64, "elevations": 16, "cameraHeight": 1e6, "range": [0, 1e7], "layout": "linear"}),
             check=fog_table(lambda d, dy: height_f(0.05, 0.2, 0, 1e6, dy, d)),
             must="the closed form with e^(−b·h) underflowing: f = 1 up high", mutation=OFF_TABLE),
        fog_points("HEIGHT, horizontal rays inside the layer", HEIGHT, [[1e3, 0, 0], [1e6, 0, 0], [0, 0, -50]],
                   "b·Δh → 0: exp(−a·d) at the camera's density (e^−50, 0, e^−2.5)", mutation=OFF_SAMPLES),
    ]


def sample_rows():
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

    def first_region(answers, server):  # the point inside both spheres given to the first that holds it
        answers[0][1]["samples"][0].update(region=0, factor=exp_neg(1e-200, 2e-200))
    return [
        fog_points("GL_EXP, density 1e300, points 1e-300 … 3e-300 away", {"fogType": "GL_EXP", "density": 1e300},
                   [[1e-300, 0, 0], [0, 2e-300, 0], [1e-300, -1e-300, 0], [0, 0, -3e-300]],
                   "f = e^(−ρ·d) = e^−1, e^−2, e^−√2, e^−3: |p − c| with no square of 1e-300 (a naive one is 0: f = 1)",
                   mutation=OFF_SAMPLES),
        fog_points("GL_EXP2, density 1e-200, points 1e200 and 5e199 away", {"fogType": "GL_EXP2", "density": 1e-200},
                   [[1e200, 0, 0], [0, 5e199, 0], [-6e199, 0, 8e199]],
                   "f = e^(−(ρ·d)²) = e^−1, e^−0.25, e^−1: d² = 1e400 never formed", mutation=OFF_SAMPLES),
        fog_points("HEIGHT, level rays 1e150, 1e160, 1e200 away", HEIGHT,
                   [[1e150, 0, 0], [0, 0, 1e160], [1e200, 0, 0], [-1e200, 0, 1e200]],
                   "τ = a·d on level rays at the layer's base: f = 0 (a naive |p − c| = ∞ gives 1)", mutation=OFF_SAMPLES),
        fog_points("HEIGHT, density 1e170, points 1e-170 and 2e-170 away", {**HEIGHT, "density": 1e170},
                   [[1e-170, 0, 0], [0, 0, -2e-170]], "τ = a·d = 1, 2: f = e^−1, e^−2", mutation=OFF_SAMPLES),
        fog_points("DISTANCE_EXP2, d_c = 5e-324 (the denormal), d = 5e161 … 2e162", {"fogType": "DISTANCE_EXP2",
                   "distanceCoefficient": dc}, far, f"f = exp(−exp(ln d_c + 2 ln d)) = {far_f}: d² overflows past 1.3e154",
                   mutation=OFF_SAMPLES),
        fog_points("DISTANCE_GAUSSIAN, d_c = 5e-324, peak 0.5, d = 5e161 … 2e162",
                   {"fogType": "DISTANCE_GAUSSIAN", "distanceCoefficient": dc, "peak": 0.5}, far,
                   "f = peak·exp(−d_c·d²), in log space", mutation=OFF_SAMPLES),
        fog_points("EXPONENTIAL (X3D), visibilityRange 1e-300", {"fogType": "EXPONENTIAL", "visibilityRange": 1e-300},
                   [[3e-301, 4e-301, 0], [2.5e-301, 0, 0], [0, 9e-301, 0], [0, 0, 2e-300]],
                   "f = exp(−d/(V − d)) = e^−1, e^−1/3, e^−9, then 0 past V", mutation=OFF_SAMPLES),
        fog_points("EXPONENTIAL (X3D), visibilityRange 1e300", {"fogType": "EXPONENTIAL", "visibilityRange": 1e300},
                   [[3e299, 4e299, 0], [2.5e299, 0, 0], [0, 9e299, 0], [1e300, 1e300, 0]],
                   "f = exp(−d/(V − d)) = e^−1, e^−1/3, e^−9, then 0 past V", mutation=OFF_SAMPLES),
        fog_points("LINEAR (X3D), visibilityRange 1e-300", {"fogType": "LINEAR", "visibilityRange": 1e-300},
                   [[1.5e-301, 2e-301, 0], [0, 5e-301, 0], [0, 0, 2e-300]], "f = (V − d)/V = 0.75, 0.5, 0",
                   mutation=OFF_SAMPLES),
        fog_points("LINEAR (X3D), visibilityRange 1e300", {"fogType": "LINEAR", "visibilityRange": 1e300},
                   [[1.5e299, 2e299, 0], [0, 5e299, 0], [1e300, 1e300, 0]], "f = (V − d)/V = 0.75, 0.5, 0",
                   mutation=OFF_SAMPLES),
        fog_points("GL_LINEAR, start 1e-300, end 3e-300", {"fogType": "GL_LINEAR", "start": 1e-300, "end": 3e-300},
                   [[5e-301, 0, 0], [0, 2e-300, 0], [1.5e-300, 2e-300, 0], [0, 0, 4e-300]],
                   "clamp((end − d)/(end − start)) = 1, 0.5, 0.25, 0", mutation=OFF_SAMPLES),
        fog_points("GL_LINEAR, start 1e299, end 1e300, camera at x = −5e299", {"fogType": "GL_LINEAR", "start": 1e299, "end": 1e300},
                   [[0, 0, 0], [5e299, 0, 0], [-5e299, 3e299, 4e299], [-5e299, 5e298, 0]],
                   "clamp((end − d)/(end − start)) = 5/9, 0, 5/9, 1", camera=(-5e299, 0, 0), mutation=OFF_SAMPLES),
        fog_points("ATMOSPHERIC, extinction 1e-300, 1, 300, inscattering 300, 1, 1e-300, d = 1e-300 … 1.7e300",
                   {"fogType": "ATMOSPHERIC", "extinction": [1e-300, 1, 300], "inscattering": [300, 1, 1e-300]},
                   [[1e-300, 0, 0], [0, 2e-3, 0], [3e299, 4e299, 0], [1e300, 0, 0], [1e300, 1e300, 1e300]],
                   "per channel T = e^(−β_e·d) (e^−1 at β 1e-300, d 1e300), fog colour = color·(1 − e^(−β_i·d)); f = mean T",
                   mutation=OFF_SAMPLES),
        fog_points("GL_EXP 1e300 with a sun (exponent 2, direction 1e-300 long), d = 1e-300 …",
                   {"fogType": "GL_EXP", "density": 1e300,
                    "directional": {"color": [1, 0.8, 0.6], "direction": [0, 0, -1e-300], "exponent": 2}},
                   [[0, 0, -1e-300], [1e-300, 0, -1e-300], [0, 2e-300, 0]],
                   "T = f per channel; fog colour = (1 − f)·(color + sun·max(cos θ, 0)²): lobes 1, 0.5, 0",
                   mutation=OFF_SAMPLES),
        fog_points("GL_EXP2 1e-200 with a sun (Henyey–Greenstein g 0.5, direction 1e300 long), d = 5e199 …",
                   {"fogType": "GL_EXP2", "density": 1e-200,
                    "directional": {"color": [1, 0.8, 0.6], "direction": [1e300, 0, 0], "g": 0.5}},
                   [[1e200, 0, 0], [0, 1e200, 0], [-5e199, 0, 0]],
                   "fog colour = (1 − f)·(color + sun·(1 − g²)/(1 + g² − 2g cos θ)^1.5): lobes 6, 0.54, 0.22",
                   mutation=OFF_SAMPLES),
        fog_points("HEIGHT, slanted rays 5e199 … 1e200 long", HEIGHT, [[1e200, 1e199, 0], [1e200, -1e199, 0], [3e199, 4e199, 0]],
                   "height_f with d_y from a scaled norm: rising rays see τ → a/(b·d_y) (f = 0.081, 0.73), "
                   "the falling one f = 0", mutation=OFF_SAMPLES),
        fog_points("HEIGHT, density and falloff 1e300, rays 5e-300 long, camera 1e-300 up",
                   {**HEIGHT, "density": 1e300, "heightFalloff": 1e300},
                   [[3e-300, 5e-300, 0], [3e-300, -3e-300, 0], [5e-300, 1e-300, 0]],
                   "height_f: b·d_y·t = ±4 and 0 (f = 0.64, 2e-11, 0.16): every product of a 1e300 and a 1e-300 in log space",
                   camera=(0, 1e-300, 0), mutation=OFF_SAMPLES),
        fog_points("HEIGHT in Filament's convention, 1e-299 away (|b·v_y| = 6e-4)", fil_tiny, [tiny_pt],
                   f"Filament's f = e^(−σ(c_y)·d) = e^−5 below its 0.00125 guard (§2.4 F2), not the exact {effectd_f:.6g}",
                   mutation=Mutation(f"effectd's exact integral {effectd_f:.6g} (the convention ignored)",
                                     lambda answers, server: answers[0][1]["samples"][0].update(factor=effectd_f))),
        fog_points("HEIGHT in Filament's convention, 5e199 … 1e200 away", {**HEIGHT, "convention": "filament"},
                   [[1e200, 1e199, 0], [3e199, 4e199, 0], [1e200, -1e-3, 0]],
                   "Filament's τ = σ(c_y)·d·(1 − e^(−b·v_y))/(b·v_y): f = 0.081, 0.73, and 0 on the near-level ray",
                   mutation=OFF_SAMPLES),
        fog_points("regions: spheres of radius 1e200 and 1e-200 (nested)", {"fogType": "GL_EXP2", "density": 1e-200},
                   [[2e-200, 0, 0], [2e-200, 5e-201, 0], [2e-200, 1.5e-200, 0], [5e199, 5e199, 0], [1e200, 1e200, 0]],
                   "the innermost region (log volumes: 1e-600 against 1e600): 1, 1, 0, 0, −1 (global), each with its own "
                   "fog: f = e^−2, e^−2.06, 1, e^−0.71, e^−2", regions=[big, small],
                   mutation=Mutation("the point inside both spheres given to the first (region 0)", first_region)),
    ]


# ---- warped HEIGHT tables (docs/using/fog.md §4; fog.h WarpedAxes) -------------------------------
def warped_table(bodies):
    """Every entry of warped HEIGHT tables against height_f at the (distance, y) that the answer's
    axes put it at (row v_j = j/(rows − 1) -> y = sinh((2v − 1)·asinh k)/k; column u_i = i/(size − 1)
    -> d = start + u·span(y)); the axes checked against the request where the request fixes them
    (falloff, range, k in [1, 1e6]); and each row long enough: a lookup past its last column
    clamps there, which is within 1/255 of the closed form out to the range's end (docs/using/fog.md
    §5) only if f(last column) − f(end) ≤ 1/255 (f falls with d). Its mutation: linear_instead(bodies)."""
    def check(answers, server):
        seen, bad, n, errs, rels, lo = [], [], 0, [0.0], [0.0], math.inf
        for body, (s, a) in zip(bodies, answers):
            if s != 200:
                return False, f"status {s}: {message(a)}"
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
    return check


def linear_instead(bodies):
    """The same requests in the linear layout (asked of the server): its entries under warped axes."""
    def change(answers, server):
        for k, body in enumerate(bodies):
            lin = copy.deepcopy(body)
            lin["table"]["layout"] = "linear"
            s, a, _ = server.post("/v1/fog", lin)
            answers[k][1]["table"]["factor"] = a["table"]["factor"]
    return Mutation("the linear table's entries (the layout ignored) under the warped axes", change)


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
        case("fog", "HEIGHT, warped 64 × 32, camera at 2", "fog", w1, check=warped_table(w1),
             must="every entry = height_f at the (d, y) its axes give, within 2e-6 and 1e-5 relative (float32); each row "
             "out to its fog's completeness or the range's end", mutation=linear_instead(w1)),
        case("fog", "HEIGHT, warped, density 1e300, camera 3 above and 3 below the layer", "fog", w2, check=warped_table(w2),
             must="downward rows' columns 1e-299 long (κ at its e^−690 floor), f at each = height_f; level and rising rows "
             "0 past d = 0; every row out to completeness", mutation=linear_instead(w2)),
        case("fog", "HEIGHT, warped, falloff 100 (a 1 cm layer), camera 0.5 above it", "fog", w3, check=warped_table(w3),
             must="κ = e^59: the straight-down row's columns end 0.89 away, past the layer; the level and rising rows reach "
             "the default range's end (5.7e23, where the level ray's fog is complete); every entry = height_f",
             mutation=linear_instead(w3)),
        case("fog", "HEIGHT, warped, camera 300 above the layer, range [0, 1e5]", "fog", w4, check=warped_table(w4),
             must="σ at the camera e^−60·a: the downward rows' columns run past where they reach the layer; every entry = "
             "height_f, none short of the fog's completeness", mutation=linear_instead(w4)),
        case("fog", "HEIGHT, warped, camera 1000 above the layer, range [0, 1e5]", "fog", w5, check=warped_table(w5),
             must="κ would be e^203, beyond a float: κ 0 (even columns), so every downward row runs to the range's end and "
             "meets the fog (κ clamped at e^69 ended them short at f = 1); every entry = height_f",
             mutation=linear_instead(w5)),
    ]


# ---- Unreal's convention (docs/effects.md §2.4, U1-U4) -------------------------------------------
def effectd_instead(f, camera, points):
    """A mutation: each sample's f as effectd's exact integral would give it (the convention ignored)."""
    ef = {k: v for k, v in f.items() if k != "convention"}

    def change(answers, server):
        for x, p in zip(answers[0][1]["samples"], points):
            x["factor"] = fog_model(ef, camera, p)[0]
    return Mutation("effectd's exact integral (the convention ignored)", change)


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
                   camera=high, mutation=effectd_instead(UNREAL, high, high_pts)),
        fog_points("HEIGHT in Unreal's convention, density 1e-42, falls of 1e6 and 1e7", steep, steep_pts,
                   f"B·v_y clamped at −127 (U3) on the falls, the Taylor term on the level ray (U2): f = {fs} "
                   f"(effectd: {es})",
                   mutation=effectd_instead(steep, (0, 0, 0), steep_pts)),
        fog_points("HEIGHT in Unreal's convention, density 1e300, points 1e-300 … 1.4e200 away", ub, ub_pts,
                   "A'·L from 1e300·2^0 and 1e-300: f = " + ", ".join(f"{unreal_f(ub, (0, 0, 0), p):.3g}" for p in ub_pts),
                   mutation=Mutation("the farthest f in (0, 1) ×0.99", OFF_SAMPLES.change)),
        case("fog", "HEIGHT in Unreal's convention: table, camera 1e5 (observer at 65536), range [0, 1e6]", "fog",
             fog(ut, table={"size": 32, "elevations": 9, "cameraHeight": 1e5, "range": [0, 1e6], "layout": "linear"}),
             check=fog_table(lambda d, dy: unreal_f(ut, (0, 1e5, 0), (d * math.sqrt(max(0.0, 1 - dy * dy)), 1e5 + d * dy, 0))),
             must="every entry = Unreal's f (U2-U4 written out here) within 2e-6 and 1e-5 relative (float32)",
             mutation=OFF_TABLE),
    ]


def cases(quick):
    """Fog's rows (the same at both sizes: none is heavy)."""
    return table_rows() + sample_rows() + warped_rows() + unreal_rows()

