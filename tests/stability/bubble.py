"""The bubble's stiff and extreme cases: eqn 8's final vectors past the critical angle, thin films
at thickness 0 and at air's index, the wobble at 1e9 s and at its bound, sizes from 1e-6 to 1e6,
a drained film, and the exact 4xx. Each row names its mutation."""
import math

from stability.closed_forms import fresnel_r, ray
from stability.common import Mutation, case, ok_status, parent_named, problem, statuses, worst
from sweep_test import check_bubble


def faint_film(n2):
    """Each row of the thin-film table within the two interfaces' Fresnel bound (mutation: FILM_TWICE)."""
    def check(answers, server):
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


def _film_twice(answers, server):
    t = answers[0][1]["thinFilm"]
    t.update(rgb=[2 * v for v in t["rgb"]])


FILM_TWICE = Mutation("the film's rgb ×2 (its reflectance counted twice)", _film_twice)


def bubble_scale_invariant(radii):
    """The same shape at every radius (its mutation: nudged_at(radii[-1]))."""
    def check(answers, server):
        if not ok_status(200, answers):
            return False, statuses(answers)
        shapes = [[v / r for v in a["mesh"]["positions"]] for r, (_, a) in zip(radii, answers)]
        err = max(worst(s, shapes[0]) for s in shapes[1:])
        return err <= 1e-5, f"max |p/r at radius {radii[1]:g} − p/r at {radii[0]:g}| = {err:.2g}"
    return check


def nudged_at(radius):
    def nudge(answers, server):
        answers[-1][1]["mesh"]["positions"][0] += 1e-4 * radius
    return Mutation(f"one vertex nudged by 1e-4 radii at radius {radius:g}", nudge)


def checked_by_sweep(body):
    """tests/sweep_test.py's check_bubble: every triangle oriented as on the undisturbed sphere (asked
    of the server: the same request without wobble), none degenerate (mutation: FOLDED)."""
    def check(answers, server):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        probs = check_bubble(body, a, server)
        return not probs, "every triangle oriented as on the undisturbed sphere, none degenerate" if not probs else probs[0]
    return check


def _fold(answers, server):
    mesh = answers[0][1]["mesh"]
    p, (i, j) = mesh["positions"], mesh["indices"][:2]
    p[3 * i:3 * i + 3], p[3 * j:3 * j + 3] = p[3 * j:3 * j + 3], p[3 * i:3 * i + 3]


FOLDED = Mutation("the first triangle folded over (two of its corners swapped)", _fold)


def thin_film_zero_and_air(answers, server):
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


def zero_film_reflects(answers, server):
    t = answers[0][1]["thinFilm"]
    t["rgb"][3 * t["width"]] = 0.01  # row 1 (off grazing), column 0 (thickness 0), red


def _eqn8_weights(body):
    prm = body["params"]
    alpha = min(1.0, max(0.0, prm.get("muSpeed", 0.05) * body["time"]))
    return 1 + (0.1 - 1) * alpha, 0.1 + (1 - 0.1) * alpha  # mu_top, mu_bottom


def final_vectors(body):
    """Eqns 4-8 per vertex from the answer's own positions and normals, written out here: I the unit
    ray from the camera, γ = N·V, ν_in = (n1/n2)·√(1 − γ²); Final = R·μ_top + T, R = I + 2γN,
    T = (η·I + (η·γ − γ_in)·N)·μ_bottom while ν_in < 1, else 0 (TIR); α = min(1, 0.05·t). Its
    mutation: unweighted(body)."""
    prm = body["params"]
    n1, n2, cam = prm.get("n1", 1.0), prm.get("n2", 1.33), body["camera"]
    mu_top, mu_bottom = _eqn8_weights(body)

    def check(answers, server):
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
    return check


def unweighted(body):
    mu_top, _ = _eqn8_weights(body)

    def change(answers, server):
        f = answers[0][1]["mesh"]["finalVectors"]
        f[0:3] = [x / mu_top for x in f[0:3]]
    return Mutation("one final vector without eqn 8's weight μ_top", change)


def drained_film(h_nm):
    """A film drained to H(t) = h_nm: every texel in [0, H] (h = H·√s, s in [0, 1], wherever the
    swirl brought the film from), finite, and its bottom near H (max ≥ 0.9 H). Mutation: UNDRAINED."""
    def check(answers, server):
        s, a = answers[0]
        if s != 200:
            return False, f"status {s}"
        nm = a["thickness"]["nm"]
        ok = all(math.isfinite(v) and 0 <= v <= h_nm * (1 + 1e-6) for v in nm) and max(nm) >= 0.9 * h_nm
        return ok, f"thickness in [{min(nm):.4g}, {max(nm):.4g}] nm (H = {h_nm:g} nm)"
    return check


def _undrained(answers, server):
    t = answers[0][1]["thickness"]
    t.update(nm=[v * 10 / 3 for v in t["nm"]])


UNDRAINED = Mutation("the undrained film's thickness (H = 1000 nm: ×10/3)", _undrained)


def same_mesh_late(answers, server):
    (_, a), (_, b) = answers[0], answers[1]
    err = worst(a["mesh"]["positions"], b["mesh"]["positions"])
    return ok_status(200, answers) and err <= 1e-5, f"max |p(1e9) − p(1e9 mod π)| {err:.2g}"


def cases(quick):
    bub = {"time": 1, "camera": [0, 0, 3], "params": {"n1": 1.5, "n2": 1.0, "wobbleAmplitude": 0.05},
           "mesh": {"level": 3, "radius": 1}, "include": ["mesh"]}
    wob = {"time": 7, "camera": [0, 0, 3], "params": {"wobbleAmplitude": 0.1, "wobbleFrequency": 5},
           "mesh": {"level": 2, "radius": 1}, "include": ["mesh"]}
    return [
        case("bubble", "grazing view, TIR (n₁ 1.5 outside, n₂ 1.0)", "bubble", bub, check=final_vectors(bub),
             must="eqn 8 past the critical angle (T = 0): every vertex's final vector equals R·μ_top + T computed here "
             "from its position and normal (within 1e-5), finite at the silhouette", mutation=unweighted(bub)),
        case("bubble", "film thickness 0 … 1e4 nm; n₂ = 1", "bubble",
             [{"features": {"iridescence": True}, "thinFilm": {"thicknessRange": [0, 10000], "width": 64, "height": 16},
               "include": ["thinFilm"]},
              {"features": {"iridescence": True}, "params": {"n2": 1}, "thinFilm": {"width": 16, "height": 16},
               "include": ["thinFilm"]}],
             check=thin_film_zero_and_air,
             must="thickness 0 reflects nothing (1 only at grazing); a film of air's index reflects nothing",
             mutation=Mutation("thickness 0 reflecting 1 % off grazing", zero_film_reflects)),
        case("bubble", "n₂ = 1 + 1e-6: a film barely denser than air", "bubble",
             {"features": {"iridescence": True}, "params": {"n2": 1 + 1e-6}, "thinFilm": {"width": 16, "height": 16},
              "include": ["thinFilm"]}, check=faint_film(1 + 1e-6),
             must="each row at most the two interfaces' Fresnel bound (|r₁₂| + |r₂₃|)² ≈ 4r² (×1.5 for sRGB's "
             "out-of-gamut reach): 1e-12 at normal incidence, more towards grazing; no colour, no 0/0",
             mutation=FILM_TWICE),
        case("bubble", "t = 1e9 s", "bubble",
             [{"time": t, "camera": [0, 0, 3], "params": {"wobbleAmplitude": 0.05}, "mesh": {"level": 2, "radius": 1},
               "include": ["mesh"]} for t in (1e9, math.fmod(1e9, math.pi))],
             check=same_mesh_late,
             must="the wobble's phase δ·t reduced mod 2π in double: the mesh at 1e9 s equals the mesh at 1e9 mod π s (δ = 2)",
             mutation=Mutation("one vertex at 1e9 s nudged by 1e-4", lambda answers, server: answers[0][1]["mesh"]["positions"]
                               .__setitem__(0, answers[0][1]["mesh"]["positions"][0] + 1e-4))),
        case("bubble", "wobble at its bound (amplitude × frequency 0.5), t = 7", "bubble", wob, check=checked_by_sweep(wob),
             must="dented, never folded: no triangle inverted or degenerate", mutation=FOLDED),
        case("bubble", "the paper's literal wobble (amplitude 1, frequency 1)", "bubble",
             {"time": 7, "params": {"wobbleVariant": "paper", "wobbleAmplitude": 1}, "include": ["mesh"]},
             check=problem(422, "/params/wobbleAmplitude"), must="its Jacobian reaches 0: a 422 naming the field",
             mutation=parent_named(422, "/params/wobbleAmplitude")),
        case("bubble", "radius 1e-6 under the paper's wobble of 0.05", "bubble",
             {"time": 1, "params": {"wobbleVariant": "paper", "wobbleAmplitude": 0.05}, "mesh": {"level": 2, "radius": 1e-6},
              "include": ["mesh"]},
             check=problem(422, "/mesh/radius"),
             must="float32 cannot hold the shape: a 422 naming the radius, not a collapsed mesh",
             mutation=parent_named(422, "/mesh/radius")),
        case("bubble", "radius 1e-6 and 1e6, relative wobble", "bubble",
             [{"time": 7, "mesh": {"level": 2, "radius": r}, "include": ["mesh"]} for r in (1e-6, 1e6)],
             check=bubble_scale_invariant([1e-6, 1e6]),
             must="the same shape at every size (positions / radius equal within 1e-5)", mutation=nudged_at(1e6)),
        case("bubble", "film swirl 10, swirl speed 1e6, t = 1e12", "bubble",
             {"time": 1e12, "film": {"swirl": 10, "swirlSpeed": 1e6, "width": 32, "height": 16}, "include": ["thickness"]},
             check=drained_film(300),
             must="drained (α = 1 past 20 s): every texel within the profile's [0, H] = [0, 300] nm, its bottom near 300",
             mutation=UNDRAINED),
    ]
