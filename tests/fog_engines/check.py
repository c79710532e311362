#!/usr/bin/env python3
"""Checks the two engine transcriptions against the maths they claim, and measures where each
engine and effectd's current HEIGHT fog (effectd_ref.py) part ways. Standard library only, about
a second of CPU:

    python3 tests/fog_engines/check.py

Exit status 0 when every "same" claim of filament.py / unreal.py holds; the differences (F1-F7,
U2-U7 in the docstrings) are printed, not asserted.
"""
import math
import sys

import effectd_ref
import filament
import unreal

failures = []


def check(ok, what):
    print(("ok    " if ok else "FAIL  ") + what)
    if not ok:
        failures.append(what)


def midpoint(sigma, origin, direction, t0, t1, steps=20000):
    """Integral of sigma(height) along origin + t direction (direction unit, y or z up given by sigma)."""
    if t1 <= t0:
        return 0.0
    dt = (t1 - t0) / steps
    return sum(sigma(origin, direction, t0 + (i + 0.5) * dt) for i in range(steps)) * dt


def rays(camera, up_axis, elevations, distances):
    """Points at `distances` along unit directions whose up component is each of `elevations`."""
    out = []
    for e in elevations:
        h = math.sqrt(max(0.0, 1.0 - e * e))
        across = [a for a in range(3) if a != up_axis]
        unit = [0.0, 0.0, 0.0]
        unit[up_axis], unit[across[0]], unit[across[1]] = e, 0.6 * h, 0.8 * h
        for dist in distances:
            out.append((tuple(unit), dist, tuple(c + dist * u for c, u in zip(camera, unit))))
    return out


# ---- Filament --------------------------------------------------------------------------------
print("Filament (shaders/src/surface_fog.fs, ColorPassDescriptorSet::prepareFog)")
F = {"enabled": True, "density": 0.1, "heightFalloff": 0.5, "height": 1.0,
     "color": (0.6, 0.7, 0.8), "maximumOpacity": 1.0}
cam = (0.0, 2.0, 0.0)
elev = [-0.9, -0.3, -0.0005, 0.0, 0.0005, 0.2, 0.8]
dists = [0.5, 5.0, 30.0, 200.0]


def sigma_f(o, u, t):
    y = o[1] + u[1] * t
    return F["density"] * math.exp(-F["heightFalloff"] * (y - F["height"]))


worst_same, worst_level, worst_formula = 0.0, 0.0, 0.0
for unit, dist, p in rays(cam, 1, elev, dists):
    opacity, fog_rgb, _ = filament.fog(F, cam, p)
    f_e, s_e, _ = effectd_ref.fog(filament.to_effectd(F), cam, p)
    diff = abs(opacity - (1.0 - f_e))
    near_level = abs(F["heightFalloff"] * unit[1] * dist) <= filament.NEAR_LEVEL
    if near_level:
        worst_level = max(worst_level, diff)
    else:
        worst_same = max(worst_same, diff)
        tau = midpoint(sigma_f, cam, unit, 0.0, dist)  # s = 0: the whole ray
        worst_formula = max(worst_formula, abs(opacity - (1.0 - math.exp(-tau))))
    worst_same = max(worst_same, max(abs(a - b) for a, b in zip(fog_rgb, s_e)) if not near_level else 0.0)
check(worst_same < 2e-6, f"start 0: opacity = 1 - effectd f, fog colour = effectd S (worst {worst_same:.2e})")
check(worst_formula < 2e-6, f"start 0: opacity = 1 - exp(-integral of sigma), by quadrature (worst {worst_formula:.2e})")
check(worst_level < 2.5e-4, f"near-level guard |b v_y| <= 0.00125 (F2): worst {worst_level:.2e} (bound tau e^-tau |b v_y|/2 <= 2.3e-4)")

Fs = dict(F, distance=10.0)
worst_mean, worst_diff, where = 0.0, 0.0, None
for unit, dist, p in rays(cam, 1, elev, [12.0, 30.0, 200.0]):
    opacity, _, _ = filament.fog(Fs, cam, p)
    if abs(Fs["heightFalloff"] * unit[1] * dist) > filament.NEAR_LEVEL:
        tau_mean = (dist - 10.0) / dist * midpoint(sigma_f, cam, unit, 0.0, dist)
        worst_mean = max(worst_mean, abs(opacity - (1.0 - math.exp(-tau_mean))))
    f_e, _, _ = effectd_ref.fog(filament.to_effectd(Fs), cam, p)
    d = abs(opacity - (1.0 - f_e))
    if d > worst_diff:
        worst_diff, where = d, (unit[1], dist, opacity, 1.0 - f_e)
check(worst_mean < 2e-6, f"start 10 m: tau = (d - s)/d * tau[0, d] (F1), by quadrature (worst {worst_mean:.2e})")
print(f"      F1 start 10 m vs effectd's exact [s, d]: worst |opacity difference| {worst_diff:.3f} "
      f"(ray y {where[0]}, d {where[1]} m: Filament {where[2]:.4f}, effectd {where[3]:.4f})")

light = (0.0, 0.3, 1.0)
Fsun = dict(F, distance=10.0, inScatteringStart=5.0, inScatteringSize=8.0, maximumOpacity=0.5,
            lightColor=(1.0, 0.9, 0.8), lightIntensity=2.0)
worst = (0.0, None)
for unit, dist, p in rays(cam, 1, [0.0, 0.2], [12.0, 50.0, 400.0]):
    _, _, sun = filament.fog(Fsun, cam, p, light)
    _, _, glow = effectd_ref.fog(filament.to_effectd(Fsun, light), cam, p)
    d = max(abs(a - b) for a, b in zip(sun, glow))
    if d > worst[0]:
        worst = (d, (unit[1], dist, sun[0], glow[0]))
print(f"      F3 sun (start 5 < fog start 10, maxOpacity 0.5): worst |red difference| {worst[0]:.3f} "
      f"(ray y {worst[1][0]}, d {worst[1][1]} m: Filament {worst[1][2]:.4f}, effectd {worst[1][3]:.4f})")

lin = dict(F, linearFog=True, distance=2.0)
op_lin, _, _ = filament.fog(lin, cam, (30.0, 2.0, 0.0))
f_e, _, _ = effectd_ref.fog(filament.to_effectd(lin), cam, (30.0, 2.0, 0.0))
print(f"      F6 linearFog, level ray 30 m: opacity {op_lin:.4f} vs effectd exponential {1 - f_e:.4f}")
op_nan, _, _ = filament.fog(lin, (0.0, 1.0, 0.0), (30.0, 1.0, 0.0))
check(math.isnan(op_nan), "F6 linearFog with the camera exactly at `height` and heightFalloff > 0: NaN (0/0 in prepareFog)")

# ---- Unreal ----------------------------------------------------------------------------------
print("Unreal (HeightFogCommon.ush GetExponentialHeightFog, FogRendering.cpp InitFogConstants)")
U = {"FogDensity": 0.5, "FogHeightFalloff": 0.2, "FogHeight": 100.0,
     "SecondFogData": {"FogDensity": 0.3, "FogHeightFalloff": 1.0, "FogHeightOffset": 500.0},
     "FogInscatteringLuminance": (0.5, 0.6, 0.7), "FogMaxOpacity": 0.95, "StartDistance": 500.0}
ucam = (0.0, 0.0, 300.0)
uelev = [-0.9, -0.1, -0.00002, 0.0, 0.00002, 0.05, 0.5, 0.95]
udists = [100.0, 1000.0, 10000.0, 100000.0]
A = [unreal.LN2 ** 2 * U["FogDensity"] / 1000.0, unreal.LN2 ** 2 * U["SecondFogData"]["FogDensity"] / 1000.0]
B = [unreal.LN2 * U["FogHeightFalloff"] / 1000.0, unreal.LN2 * U["SecondFogData"]["FogHeightFalloff"] / 1000.0]
H = [U["FogHeight"], U["FogHeight"] + U["SecondFogData"]["FogHeightOffset"]]


def sigma_u(o, u, t):
    z = o[2] + u[2] * t
    return sum(a * math.exp(-b * (z - h)) for a, b, h in zip(A, B, H))


worst_same, worst_quad = 0.0, 0.0
for unit, dist, p in rays(ucam, 2, uelev, udists):
    f_u, fog_rgb, _ = unreal.fog(U, ucam, p)
    fog_e = unreal.to_effectd(U)
    f_e, s_e, _ = effectd_ref.fog(fog_e, unreal.to_effectd_point(ucam), unreal.to_effectd_point(p))
    worst_same = max(worst_same, abs(f_u - f_e), max(abs(a - b) for a, b in zip(fog_rgb, s_e)))
    if dist <= 10000.0:
        tau = midpoint(sigma_u, ucam, unit, U["StartDistance"], dist)
        worst_quad = max(worst_quad, abs(f_u - max(math.exp(-tau), 1.0 - U["FogMaxOpacity"])))
check(worst_same < 1e-5, f"two layers, start 5 m, cap 0.95: f = effectd f with a = ln2^2 D/1000, b = ln2 B/1000 per cm (worst {worst_same:.2e})")
check(worst_quad < 1e-6, f"f = max(exp(-integral over [s, L] of sigma), 1 - FogMaxOpacity), by quadrature (worst {worst_quad:.2e})")

Uc = dict(U, FogCutoffDistance=20000.0)
f_in, _, _ = unreal.fog(Uc, ucam, (19000.0, 0.0, 300.0))
f_out, _, _ = unreal.fog(Uc, ucam, (21000.0, 0.0, 300.0))
f_e_in, _, _ = effectd_ref.fog(unreal.to_effectd(Uc), unreal.to_effectd_point(ucam), unreal.to_effectd_point((19000.0, 0.0, 300.0)))
check(abs(f_in - f_e_in) < 1e-5 and f_out == 1.0, "FogCutoffDistance: same as effectd's cutoffDistance (f = 1 beyond)")

high = (0.0, 0.0, 100000.0)  # 1 km up: above FogHeight + 65536 cm
p = (50000.0, 0.0, 0.0)
f_u, _, _ = unreal.fog(U, high, p)
f_e, _, _ = effectd_ref.fog(unreal.to_effectd(U), unreal.to_effectd_point(high), unreal.to_effectd_point(p))
print(f"      U4 camera 1 km up, looking down 500 m away and 1 km below: Unreal f {f_u:.4f}, effectd {f_e:.4f}")

Ue = dict(U, EndDistance=20000.0, FogMaxOpacity=1.0, StartDistance=0.0, FogDensity=0.05,
          SecondFogData={"FogDensity": 0.0})
p = (60000.0, 0.0, 300.0)  # 600 m away, level
f_u, _, _ = unreal.fog(Ue, ucam, p)
f_e, _, _ = effectd_ref.fog(unreal.to_effectd(Ue), unreal.to_effectd_point(ucam), unreal.to_effectd_point(p))
print(f"      U5 EndDistance 200 m, level point 600 m away: Unreal f {f_u:.4f}, effectd {f_e:.4f}")

sun = (0.3, 0.0, 0.2)
Ud = dict(U, FogMaxOpacity=0.6, DirectionalInscatteringExponent=8.0, DirectionalInscatteringStartDistance=2000.0,
          DirectionalInscatteringLuminance=(1.0, 0.9, 0.7), SunLightColor=(3.0, 3.0, 3.0))
worst = (0.0, None)
for unit, dist, p in rays(ucam, 2, [0.0, 0.1], [3000.0, 10000.0, 100000.0]):
    _, _, glow_u = unreal.fog(Ud, ucam, p, sun)
    _, _, glow_e = effectd_ref.fog(unreal.to_effectd(Ud, sun), unreal.to_effectd_point(ucam), unreal.to_effectd_point(p))
    d = max(abs(a - b) for a, b in zip(glow_u, glow_e))
    if d > worst[0]:
        worst = (d, (unit[2], dist, glow_u[0], glow_e[0]))
print(f"      U6/U7 glow (start 5 m + 20 m, cap 0.6): worst |red difference| {worst[0]:.3f} "
      f"(ray z {worst[1][0]}, d {worst[1][1] / 100:.0f} m: Unreal {worst[1][2]:.4f}, effectd {worst[1][3]:.4f})")

print("all claims hold" if not failures else f"{len(failures)} claim(s) failed")
sys.exit(1 if failures else 0)
