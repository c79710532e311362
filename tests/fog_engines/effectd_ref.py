"""effectd's own HEIGHT fog as it is today (effects/fog/fog.cpp at cea8743), in Python, so that
filament.py and unreal.py can be compared with it without building anything.

Transcribed from effectd's fog.cpp: heightOpticalDepth (log space, g(x) = (1 - e^-x)/x),
heightDepth (both layers over [startDistance, d]), engineLimits (cutoff, then the maxOpacity
floor), factorAtElevation, inscatterWeight (the glow over [max(start, directional.start), d],
under the same cap and cutoff) and lobe (4 pi Henyey-Greenstein, or max(cos, 0)^exponent).

A fog is a dict with effectd's wire names (server/api/api_fog.cpp parseFog):
    fogType "HEIGHT", color, density, heightFalloff, baseHeight, startDistance, maxOpacity,
    cutoffDistance (absent = infinity), secondLayer {density, heightFalloff, baseHeight},
    directional {color, direction, g, exponent, startDistance}.
Defaults are fog.h's. y is up.
"""
import math

INF = math.inf

DEFAULTS = {"color": (1.0, 1.0, 1.0), "density": 1.0, "heightFalloff": 0.1, "baseHeight": 0.0,
            "startDistance": 0.0, "maxOpacity": 1.0, "cutoffDistance": INF}
LAYER_DEFAULTS = {"density": 0.0, "heightFalloff": 0.1, "baseHeight": 0.0}
DIRECTIONAL_DEFAULTS = {"color": (1.0, 0.8, 0.6), "direction": (0.0, 0.0, -1.0), "g": 0.7,
                        "exponent": None, "startDistance": 0.0}


def _get(fog, key):
    return fog.get(key, DEFAULTS[key])


def log_g(x):
    """log((1 - e^-x)/x), stable for every real x (fog.cpp logG)."""
    if x == 0.0:
        return 0.0
    if x > 0.0:
        return math.log(-math.expm1(-x)) - math.log(x)
    if x > -700.0:
        return math.log(math.expm1(-x)) - math.log(-x)
    return -x - math.log(-x)


def height_optical_depth(a, b, h, origin_y, dir_y, t):
    """Exact optical depth of a e^(-b (y - h)) along a ray of unit y component dir_y, length t."""
    if a == 0.0 or t == 0.0:
        return 0.0
    if b == 0.0:
        return a * t
    k = b * dir_y
    log_base = math.log(a) - b * (origin_y - h)
    if math.isinf(t):
        if k <= 0.0:
            return INF
        log_tau = log_base - math.log(k)
    else:
        log_tau = log_base + math.log(t) + log_g(k * t)
    return INF if log_tau > 709.0 else math.exp(log_tau)


def height_depth(fog, origin_y, dir_y, distance):
    """Both layers' optical depth over [startDistance, distance]."""
    s = min(_get(fog, "startDistance"), distance)
    y = origin_y + dir_y * s if s > 0.0 else origin_y
    t = distance - s
    tau = height_optical_depth(_get(fog, "density"), _get(fog, "heightFalloff"), _get(fog, "baseHeight"), y, dir_y, t)
    layer = fog.get("secondLayer")
    if layer is not None:
        l = dict(LAYER_DEFAULTS, **layer)
        tau += height_optical_depth(l["density"], l["heightFalloff"], l["baseHeight"], y, dir_y, t)
    return tau


def engine_limits(fog, distance, f):
    if distance > _get(fog, "cutoffDistance"):
        return 1.0
    return max(f, 1.0 - _get(fog, "maxOpacity"))


def factor_at_elevation(fog, origin_y, dir_y, distance):
    return engine_limits(fog, distance, math.exp(-height_depth(fog, origin_y, dir_y, distance)))


def inscatter_weight(fog, origin_y, dir_y, distance):
    d = fog.get("directional")
    if d is None:
        return 0.0
    d = dict(DIRECTIONAL_DEFAULTS, **d)
    beyond = dict(fog, startDistance=max(_get(fog, "startDistance"), d["startDistance"]))
    return 1.0 - factor_at_elevation(beyond, origin_y, dir_y, distance)


def lobe(directional, cos_theta):
    d = dict(DIRECTIONAL_DEFAULTS, **directional)
    c = min(max(cos_theta, -1.0), 1.0)
    if d["exponent"] is not None:
        return c ** d["exponent"] if c > 0.0 else 0.0
    g = d["g"]
    den = (1 - g) ** 2 + 2 * g * (1 - c) if g >= 0.0 else (1 + g) ** 2 - 2 * g * (1 + c)
    return (1 - g) * (1 + g) / (den * math.sqrt(den))


def fog(fog_, eye, point):
    """(f, S = (1 - f) color, glow) for one point: the colour is object * f + S + glow
    (fog.cpp shade, HEIGHT only)."""
    ray = [p - e for p, e in zip(point, eye)]
    d = math.sqrt(sum(r * r for r in ray))
    dir_y = min(max(ray[1] / d, -1.0), 1.0) if d > 0.0 else 0.0
    f = factor_at_elevation(fog_, eye[1], dir_y, d)
    color = _get(fog_, "color")
    s = tuple((1.0 - f) * c for c in color)
    glow = (0.0, 0.0, 0.0)
    if fog_.get("directional") is not None and d > 0.0:
        dd = dict(DIRECTIONAL_DEFAULTS, **fog_["directional"])
        n = math.sqrt(sum(x * x for x in dd["direction"]))
        cos_theta = sum(r / d * x / n for r, x in zip(ray, dd["direction"]))
        w = inscatter_weight(fog_, eye[1], dir_y, d) * lobe(dd, cos_theta)
        glow = tuple(w * c for c in dd["color"])
    return f, s, glow
