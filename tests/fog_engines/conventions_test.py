#!/usr/bin/env python3
"""fog.convention against the engines' own formulas: for each scene below, the service's
samples (f, and the fog colour S + glow with the object black) at >= 50 rays, from 20 degrees
down to 45 degrees up, grazing ones included, at distances before the start, in the fog and
beyond the cutoff, equal what the independent transcriptions in this folder compute
(filament.py, unreal.py; each names the engine source it was read from) within 1e-5.

    tests/fog_engines/conventions_test.py build/server/effectd
"""
import http.client
import json
import math
import os
import sys

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import filament  # noqa: E402
import unreal  # noqa: E402
from effectd_process import start  # noqa: E402

TOLERANCE = 1e-5
LN2 = math.log(2.0)


def rays(camera, distances):
    """(direction, distance) pairs: elevations -20..45 degrees and grazing ones, three azimuths."""
    elevations = [-20 + 65 * i / 17 for i in range(18)] + [-1e-4, -1e-7, 0.0, 1e-7, 1e-4, 0.3]
    out = []
    for k, az in enumerate((0.3, 1.9, 4.0)):
        for i, el in enumerate(elevations):
            e, a = math.radians(el), az + 0.07 * i
            d = (math.cos(e) * math.cos(a), math.sin(e), math.cos(e) * math.sin(a))
            out.append((d, distances[(i + k) % len(distances)]))
    return out


def post(port, body):
    c = http.client.HTTPConnection("127.0.0.1", port, timeout=60)
    c.request("POST", "/v1/fog", body=json.dumps(body), headers={"Content-Type": "application/json"})
    r = c.getresponse()
    data = json.loads(r.read())
    assert r.status == 200, (r.status, data)
    return data


def compare(port, name, fog, camera, cases, engine):
    """engine(direction, distance) -> (f, fog_rgb + glow_rgb) in effectd's axes."""
    points = [[camera[i] + t * d[i] for i in range(3)] for d, t in cases]
    answer = post(port, {"fog": fog, "include": ["samples"], "samples": {"camera": camera, "points": points}})
    worst = 0.0
    for (d, t), sample in zip(cases, answer["samples"]):
        f, rgb = engine(d, t)
        got = [sample["factor"]] + (sample["fogColor"] if "fogColor" in sample else [(1 - sample["factor"]) * c for c in fog["color"]])
        want = [f] + list(rgb)
        worst = max(worst, max(abs(g - w) for g, w in zip(got, want)))
    ok = worst <= TOLERANCE
    print(f"{'ok  ' if ok else 'FAIL'} {name}: {len(cases)} rays, largest difference {worst:.2e}")
    return ok


def filament_scene(port, name, params, camera, light, distances):
    fog = {"fogType": "HEIGHT", "convention": "filament", "color": list(params["color"]),
           "density": params["density"], "heightFalloff": params["heightFalloff"], "baseHeight": params["height"],
           "startDistance": params["distance"], "maxOpacity": params["maximumOpacity"]}
    if "cutOffDistance" in params:
        fog["cutoffDistance"] = params["cutOffDistance"]
    if light:
        fog["directional"] = {"color": list(params["lightColor"]), "direction": list(light),
                              "exponent": params["inScatteringSize"], "startDistance": params["inScatteringStart"]}

    def engine(d, t):
        p = tuple(camera[i] + t * d[i] for i in range(3))
        engine_params = dict(params, enabled=True)
        opacity, fog_rgb, sun = filament.fog(engine_params, tuple(camera), p, tuple(light) if light else None)
        return 1.0 - opacity, [a + b for a, b in zip(fog_rgb, sun)]
    return compare(port, name, fog, camera, rays(camera, distances), engine)


def unreal_scene(port, name, params, camera, light, distances):
    """Unreal's Z-up centimetres; effectd's axes are (x, z, y) of them, the same units."""
    swap = lambda v: [v[0], v[2], v[1]]  # noqa: E731
    o = dict(unreal.DEFAULTS, **params)
    second = dict(unreal.DEFAULTS["SecondFogData"], **params.get("SecondFogData", {}))
    fog = {"fogType": "HEIGHT", "convention": "unreal", "color": list(o["FogInscatteringLuminance"]),
           "density": LN2 * LN2 * o["FogDensity"] / 1000, "heightFalloff": LN2 * o["FogHeightFalloff"] / 1000,
           "baseHeight": o["FogHeight"], "startDistance": o["StartDistance"], "maxOpacity": o["FogMaxOpacity"]}
    if second["FogDensity"] > 0:
        fog["secondLayer"] = {"density": LN2 * LN2 * second["FogDensity"] / 1000,
                              "heightFalloff": LN2 * second["FogHeightFalloff"] / 1000,
                              "baseHeight": o["FogHeight"] + second["FogHeightOffset"]}
    if o["FogCutoffDistance"] > 0:
        fog["cutoffDistance"] = o["FogCutoffDistance"]
    if light:
        sun = unreal.luminance(params.get("SunLightColor", unreal.ENGINE_DEFAULTS["SunLightColor"]))
        fog["directional"] = {"color": [c * sun for c in o["DirectionalInscatteringLuminance"]],
                              "direction": swap(light), "exponent": o["DirectionalInscatteringExponent"],
                              "startDistance": o["DirectionalInscatteringStartDistance"]}
    cam = swap(camera)

    def engine(d, t):
        du = (d[0], d[2], d[1])
        p = tuple(camera[i] + t * du[i] for i in range(3))
        f, fog_rgb, glow = unreal.fog(params, tuple(camera), p, tuple(light) if light else None)
        return f, [a + b for a, b in zip(fog_rgb, glow)]
    return compare(port, name, fog, cam, rays(cam, distances), engine)


def main():
    proc, port = start(sys.argv[1], "--access-log", "0")
    ok = True
    try:
        ok &= filament_scene(port, "filament: the issue's scene, start 5, sun", {
            "density": 0.05, "heightFalloff": 0.2, "height": 0.0, "color": (0.6, 0.7, 0.8), "distance": 5.0,
            "maximumOpacity": 1.0, "inScatteringStart": 10.0, "inScatteringSize": 8.0, "lightColor": (1.0, 0.9, 0.7)},
            [0.0, 2.0, 0.0], (0.3, 0.2, -0.9), [1.0, 4.0, 12.0, 40.0, 150.0, 900.0])
        ok &= filament_scene(port, "filament: cap, cutoff, camera below the floor", {
            "density": 0.3, "heightFalloff": 0.8, "height": 5.0, "color": (0.9, 0.9, 1.0), "distance": 0.0,
            "maximumOpacity": 0.7, "cutOffDistance": 300.0, "inScatteringStart": 0.0, "inScatteringSize": 2.0,
            "lightColor": (2.0, 1.5, 1.0)},
            [10.0, -3.0, 4.0], (-0.5, 0.5, 0.2), [0.5, 8.0, 60.0, 299.0, 301.0, 5000.0])
        ok &= filament_scene(port, "filament: no sun, falloff 0", {
            "density": 0.02, "heightFalloff": 0.0, "height": 0.0, "color": (0.5, 0.5, 0.5), "distance": 20.0,
            "maximumOpacity": 0.9, "inScatteringStart": 0.0, "inScatteringSize": -1.0},
            [0.0, 1.0, 0.0], None, [3.0, 19.0, 21.0, 100.0, 700.0])
        ok &= unreal_scene(port, "unreal: two layers, start, sun", {
            "FogDensity": 0.02, "FogHeightFalloff": 0.2, "FogHeight": 0.0, "StartDistance": 500.0,
            "FogInscatteringLuminance": (0.45, 0.64, 1.0), "DirectionalInscatteringLuminance": (0.25, 0.25, 0.125),
            "DirectionalInscatteringExponent": 4.0, "DirectionalInscatteringStartDistance": 1000.0,
            "SecondFogData": {"FogDensity": 0.05, "FogHeightFalloff": 1.0, "FogHeightOffset": 300.0}},
            [0.0, 0.0, 200.0], (0.4, -0.8, 0.3), [100.0, 499.0, 800.0, 3000.0, 20000.0, 200000.0])
        ok &= unreal_scene(port, "unreal: cap, cutoff, camera far above (observer clamp)", {
            "FogDensity": 0.5, "FogHeightFalloff": 0.05, "FogHeight": -200.0, "FogMaxOpacity": 0.8,
            "FogCutoffDistance": 150000.0, "FogInscatteringLuminance": (0.8, 0.8, 0.9),
            "DirectionalInscatteringLuminance": (1.0, 0.5, 0.2), "DirectionalInscatteringExponent": 16.0,
            "DirectionalInscatteringStartDistance": 0.0},
            [100.0, 50.0, 90000.0], (0.0, 0.6, 0.8), [1000.0, 40000.0, 149000.0, 151000.0, 1e6])
        ok &= unreal_scene(port, "unreal: no sun, near-level rays (Taylor term)", {
            "FogDensity": 0.1, "FogHeightFalloff": 0.001, "FogHeight": 0.0, "FogMaxOpacity": 1.0,
            "FogInscatteringLuminance": (0.5, 0.6, 0.7)},
            [0.0, 0.0, 10.0], None, [50.0, 5000.0, 80000.0])
    finally:
        proc.terminate()
        proc.wait()
    sys.exit(0 if ok else 1)


if __name__ == "__main__":
    main()
