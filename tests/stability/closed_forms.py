"""The closed forms the stability checks compare the server's answers with, written out here in
Python from docs/effects.md's formulas (not the server's code): fog factors in every convention,
the APSF's series, Fresnel's bound, the warped HEIGHT table's axes, which pixels a sphere covers,
and CIE76 colour differences. Pure functions: no state."""
import math


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


# ---- the bubble: thin film, the render preview ---------------------------------------------------
def fresnel_r(cos_i, n):
    """The larger of |r_s|, |r_p| from air into index n at incidence cos_i."""
    sin2 = 1 - cos_i * cos_i
    cos_t = math.sqrt(max(0.0, 1 - sin2 / (n * n)))
    rs = (cos_i - n * cos_t) / (cos_i + n * cos_t) if cos_i + n * cos_t > 0 else 1.0
    rp = (n * cos_i - cos_t) / (n * cos_i + cos_t) if n * cos_i + cos_t > 0 else 1.0
    return max(abs(rs), abs(rp))


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
