"""The glow through fog (docs/effects.md §5): the APSF's table against its closed forms (the q = 1
generating function, the diffuse limit, the series summed here), T from a fog's ray against T
given, the halo growing with T, and the exact 4xx. Each row names its mutation."""
import math

from stability.closed_forms import apsf_py
from stability.common import Mutation, case, parent_named, problem


def glow_body(glow, fog_def=None):
    return {"fog": fog_def or {"fogType": "GL_EXP", "density": 0.01}, "glow": glow, "include": ["glow"]}


def glow_table(expected, must_direct=None, tol=2e-7):
    """Every table entry against expected(theta) within tol relative (the answer's numbers are
    floats: 6e-8) or 1e-9 absolute (the entries that should be 0), and direct = must_direct when
    given. Mutation: K0_OFF."""
    def check(answers, server):
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
    return check


def _k0_off(answers, server):
    answers[0][1]["glow"]["table"]["perSteradian"][0] *= 1.001


K0_OFF = Mutation("K(0) ×1.001", _k0_off)


def glow_invariant(answers, server):
    """The glow of a fog's ray equals the glow of its optical thickness given: T = density × length."""
    (s1, a1), (s2, a2) = answers
    if s1 != 200 or s2 != 200:
        return False, f"status {s1}, {s2}"
    g1, g2 = a1["glow"], a2["glow"]
    ok = abs(g1["opticalThickness"] - 2) <= 1e-9 and g1["table"] == g2["table"] and g1["gaussians"] == g2["gaussians"]
    return ok, f"T from the fog {g1['opticalThickness']:.12g} (2 given); tables and Gaussians equal: {g1['table'] == g2['table']}"


def halo_grows(answers, server):
    radii = [a["glow"]["haloRadiusDeg"] for s, a in answers if s == 200]
    ok = len(radii) == len(answers) and all(b > a for a, b in zip(radii, radii[1:]))
    return ok, "halo radius " + ", ".join(f"{r:.3g}°" for r in radii)


def closed_q1(t):
    """q = 1: every β_m = 0, the Legendre generating function."""
    def k(theta):
        x = 1 / t
        g = 1 / math.sqrt(1 - 2 * math.cos(theta) * x + x * x)
        return (g / t ** 2 + (g - 1) / t) * t * t / (4 * math.pi)
    return k


def diffuse(theta):
    return (1 + math.cos(theta)) / (4 * math.pi)


def cases(quick):
    table = {"kernel": "table", "samples": 19, "maxAngleDeg": 180}
    return [
        case("glow", "APSF, q = 1 (all forward), T = 1.3", "fog",
             glow_body({**table, "opticalThickness": 1.3, "forwardScattering": 1}),
             check=glow_table(closed_q1(1.3), math.exp(-1.3)),
             must="β_m = 0: the Legendre generating function, K = (G/T² + (G − 1)/T)·T²/4π, G = (1 − 2μ/T + 1/T²)^−½, "
             "within 2e-7 (the answer's floats); direct e^−T", mutation=K0_OFF),
        case("glow", "APSF, T = 1e300 (every g_m past g_1 underflows)", "fog",
             glow_body({**table, "opticalThickness": 1e300, "forwardScattering": 0.9}),
             check=glow_table(diffuse, 0.0), must="the diffuse limit (1 + μ)/4π in log space, finite; direct 0, scattered 1",
             mutation=K0_OFF),
        case("glow", "APSF, T = 0 (clear air)", "fog", glow_body({**table, "opticalThickness": 0, "forwardScattering": 0.9}),
             check=glow_table(lambda th: apsf_py(0, 0.9, math.cos(th)), 1.0),
             must="nothing scattered (direct 1, scattered 0: the halo gone); the shape at the series' floor T = 1.05, as "
             "the series summed here", mutation=K0_OFF),
        case("glow", "APSF, q = 0 (isotropic), T = 3 (0⁰ at m = 1)", "fog",
             glow_body({**table, "opticalThickness": 3, "forwardScattering": 0}),
             check=glow_table(lambda th: apsf_py(3, 0.0, math.cos(th)), math.exp(-3)),
             must="the series summed here in Python (β_1 = 0 for every q) within 2e-7 relative", mutation=K0_OFF),
        case("glow", "fog GL_EXP density 1e300 between camera and light 1 apart", "fog",
             glow_body({**table, "camera": [0, 0, 0], "source": [0, 0, -1]}, {"fogType": "GL_EXP", "density": 1e300}),
             check=glow_table(diffuse, 0.0),
             must="T = −ln 0 held at 745 (e^−745, the last double): finite, the diffuse shape, direct 0", mutation=K0_OFF),
        case("glow", "T from the fog = T given (GL_EXP 0.01 over 200)", "fog",
             [glow_body({"camera": [0, 0, 0], "source": [0, 0, -200], "forwardScattering": 0.9}),
              glow_body({"opticalThickness": 2, "forwardScattering": 0.9})],
             check=glow_invariant,
             must="an invariance: the ray's T = density·length = 2, and the same kernel as T = 2 given",
             mutation=Mutation("T from the fog 1 % off",
                               lambda answers, server: answers[0][1]["glow"].__setitem__("opticalThickness", 2.02))),
        case("glow", "halo radius against T (q 0.95): 1.2, 2, 4, 8, 40", "fog",
             [glow_body({"opticalThickness": t, "forwardScattering": 0.95, "kernel": "table", "samples": 256})
              for t in (1.2, 2, 4, 8, 40)],
             check=halo_grows, must="the half-light radius grows strictly with T (the issue's monotone halo)",
             mutation=Mutation("T 2's radius past T 4's", lambda answers, server: answers[1][1]["glow"].__setitem__(
                 "haloRadiusDeg", answers[2][1]["glow"]["haloRadiusDeg"] + 1))),
        case("glow", "neither T nor a ray", "fog", glow_body({"kernel": "gaussian"}), check=problem(400, "/glow"),
             must="a 400 naming /glow", mutation=parent_named(400, "/glow")),
    ]
