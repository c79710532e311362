"""Google Filament's large-scale fog (View::setFogOptions), one fragment at a time: an independent
transcription of the maths of its published source into Python (standard library only). Nothing
here is Filament's code; it is the same arithmetic, written out, so that effectd's C++ can be
tested against it.

Sources read (github.com/google/filament, through the stored index; no release tag could be
resolved from it, so commits are given; the shader commit is after PR #9030 "add a material
option to use linear fog calculations", merged 2025-08):
  * shaders/src/surface_fog.fs @ 18c129d295148131bdc1807f43d4f1d98b878dfb
      fog()        lines 6-98   (exponential height fog, in-scattering, blending)
      fogLinear()  lines 100-152 (the `linearFog` material option)
    (line numbers counted by hand from the stored text, +-1)
  * shaders/src/surface_main.fs @ 2e894ff6358a890b64e7bceb18fc4c88af3d168c, main():
      view = fogFromWorldMatrix * (getWorldPosition() - getWorldCameraPosition());
      FILAMENT_LINEAR_FOG selects fogLinear(), else fog()
  * filament/src/ds/ColorPassDescriptorSet.cpp, prepareFog(): the version with fogLinearParams
    (index file id 5057374595, chars ~9000-12900; commit not reported by the index) and the
    version @ c809d498c738d4f668cbd246a33b1fb6a0639caa (identical apart from fogLinearParams);
    prepareDirectionalLight() (lightDirection = -sceneSpaceDirection, lightColorIntensity =
    (color, intensity * exposure)); prepareAmbientLight() (iblLuminance = intensity * exposure)
  * filament/include/filament/Options.h @ 2fac13e154fb1a64bbca70e5857838d319957e9c,
    struct FogOptions (names, units and defaults below)
  * filament/src/details/View.cpp, FView::setFogOptions (the clamps below)
  * PRs #2256, #2274, #2284, #6602, #6805, #6827, #9030 and #9185 (open: "fix linear fog
    parameters calculation", 2025-09-04: the linear-fog slope below may change)

Parameters (`params`, FogOptions names; world units are metres, y is up):
  distance           0      fog start [m]                         (clamped >= 0)
  cutOffDistance     +inf   no fog beyond [m]
  maximumOpacity     1      opacity cap                           (clamped to [0, 1])
  height             0      fog floor ("sea level") [m]
  heightFalloff      1      [1/m]                                  (clamped >= 0)
  color              (1,1,1) linear RGB (older releases: 0.5 grey)
  density            0.1    extinction [1/m] at `height`           (clamped >= 0)
  inScatteringStart  0      sun in-scattering start [m]           (clamped >= 0)
  inScatteringSize   -1     sun lobe exponent; > 0 turns it on
  fogColorFromIbl    False  modulate color by the IBL in the view direction
  skyColor           None   (a cubemap; here: any true value, with iblSample)
  enabled            False  Filament's default: no fog at all unless True
Engine inputs that are not FogOptions (defaults make them neutral):
  iblLuminance   1.0        IndirectLight intensity * exposure (multiplies the fog colour)
  lightColor     (1,1,1)    the directional light's colour
  lightIntensity 1.0        its intensity * exposure (lightColorIntensity.w)
  linearFog      False      the material property `linearFog` (FILAMENT_LINEAR_FOG)
  iblSample      None       callable(direction, lod) -> rgb, for fogColorFromIbl / skyColor
  iblLevels      1          mip count of the IBL reflections cubemap or of skyColor
  cameraNear, cameraFar     0.1, 100 (only for the IBL mip choice)
  blendMode      "opaque"   "opaque" | "masked" | "transparent" | "add" | "multiply" | "screen"
  alpha          1.0        the fragment's alpha (blendMode "transparent")
The fog's own transform (View::setFogOptions' userWorldFromFog, the camera's worldTransform) is
taken as identity: fog space = world space.

fog(params, camera, point, light_dir) returns (opacity, fog_rgb, sun_rgb) for the fragment at
`point` seen from `camera`; light_dir points towards the light (Filament's lightDirection =
-LightManager direction), None = no directional light. Filament writes
    colour = object * (1 - opacity) + fog_rgb + sun_rgb.
Uniforms are rounded to float32 as the CPU stores them; the shader arithmetic is done in double
(a GPU's float exp/pow differ by ~1e-6 relative).

The maths (exponential mode). With c the camera, p the point, v = p - c, d = |v|, s = distance,
b = max(0, heightFalloff), a = density, sigma(y) = a e^(-b (y - height)):
    if d < s or d > cutOffDistance: no fog (opacity 0, nothing added)
    m  = sigma(c_y) (1 - e^(-b v_y)) / (b v_y)    if |b v_y| > 0.00125, else m = sigma(c_y)
       = (1/d) * integral over [0, d] of sigma along the ray: the MEAN density of the whole ray
    tau = m * max(d - s, 0)
    opacity = min(1 - e^(-tau), maximumOpacity)
    fog_rgb = color * iblLuminance * opacity            (* the IBL/sky sample when enabled)
    sun_rgb = lightColor * lightIntensity * max(dot(v/d, l), 0)^inScatteringSize
              * (1 - e^(-m * max(d - inScatteringStart, 0)))    only if inScatteringSize > 0
Linear mode (material linearFog): opacity = clamp(A d + B, 0, 1) with A = k, B = -k * distance,
    k = density                                                   if b <= FLT_EPSILON
    k = density (e^(-b e) - e^(-2 b e)) / (b e), e = c_y - height  otherwise (NaN when e = 0)
  no maximumOpacity cap, no height dependence along the ray, no sun.

Mapping to effectd's Fog (effects/include/effects/fog.h; wire names of server/api/api_fog.cpp):
  fogType HEIGHT; density <- density; heightFalloff <- max(0, heightFalloff);
  baseHeight <- height; startDistance <- distance; maxOpacity <- maximumOpacity;
  cutoffDistance <- cutOffDistance (absent when infinite); color <- color * iblLuminance;
  secondLayer: none (Filament has one layer);
  directional (only when inScatteringSize > 0 and a light exists): exponent <- inScatteringSize,
  startDistance <- inScatteringStart, color <- lightColor * lightIntensity, direction <- l.
  See to_effectd().

Where Filament differs from effectd's exact integral (effectd at cea8743):
  F1 start distance: Filament's tau = (d - s)/d * tau[0, d] (the mean density of the WHOLE ray
     times the fogged length); effectd integrates exactly over [s, d]. They agree when s = 0,
     b = 0 or the ray is level (v_y = 0); for s > 0 Filament over-fogs rays going up (denser air
     near the camera is counted) and under-fogs rays going down.
  F2 near-level guard: |b v_y| <= 0.00125 uses sigma(c_y) (0th order; relative error in tau up
     to ~6.3e-4); effectd evaluates g(x) in log space with expm1 (exact).
  F3 sun weight: 1 - e^(-m * max(d - inScatteringStart, 0)): the same mean density m, scaled by
     the length past inScatteringStart; NOT capped by maximumOpacity; its start does not take
     max() with `distance` (inScatteringStart < distance fogs the sun over a part of the ray the
     fog itself skips), but nothing at all is drawn for d < distance or d > cutOffDistance.
     effectd: 1 - f over [max(start, directional.start), d], exact, capped (f >= 1 - m), cut off.
  F4 sun colour and lobe: light colour * intensity * exposure, max(cos, 0)^inScatteringSize
     (effectd's `exponent` form; its HG default has no Filament counterpart).
  F5 fog colour * iblLuminance, and optionally * an IBL/sky texture sample (mip from depth).
  F6 linearFog: a different model altogether (above); effectd has no such mode.
  F7 skybox at d = +inf: tau = m * inf: opacity = maximumOpacity, except m = 0 (e.g. a rising
     ray whose b v_y = +inf) gives 0 * inf = NaN; effectd returns the closed-form limit.
  F8 float32 uniforms and shader arithmetic (effectd: double).
  Same as effectd: the cap (opacity <= maximumOpacity <=> f >= 1 - maxOpacity), the fog colour
  weight ((1 - f) * color), the strict cutoff (d > cutOffDistance), no fog before the start.
"""
import math

from floats import f32

INF = math.inf
FLT_EPSILON = 1.1920928955078125e-07
NEAR_LEVEL = 0.00125  # surface_fog.fs: below this |falloff * view.y| the mean density is sigma(c_y)

DEFAULTS = {
    "distance": 0.0, "cutOffDistance": INF, "maximumOpacity": 1.0, "height": 0.0,
    "heightFalloff": 1.0, "color": (1.0, 1.0, 1.0), "density": 0.1, "inScatteringStart": 0.0,
    "inScatteringSize": -1.0, "fogColorFromIbl": False, "skyColor": None, "enabled": False,
}
ENGINE_DEFAULTS = {
    "iblLuminance": 1.0, "lightColor": (1.0, 1.0, 1.0), "lightIntensity": 1.0, "linearFog": False,
    "iblSample": None, "iblLevels": 1, "cameraNear": 0.1, "cameraFar": 100.0,
    "blendMode": "opaque", "alpha": 1.0,
}


def _exp(x):
    try:
        return math.exp(x)
    except OverflowError:
        return INF


def _sub(p, q):
    return tuple(a - b for a, b in zip(p, q))


def _dot(p, q):
    return sum(a * b for a, b in zip(p, q))


def set_fog_options(params):
    """FView::setFogOptions: the options Filament keeps, with its clamps."""
    o = dict(DEFAULTS, **{k: v for k, v in params.items() if k in DEFAULTS})
    o["distance"] = max(0.0, o["distance"])
    o["maximumOpacity"] = min(max(o["maximumOpacity"], 0.0), 1.0)
    o["density"] = max(0.0, o["density"])
    o["heightFalloff"] = max(0.0, o["heightFalloff"])
    o["inScatteringStart"] = max(0.0, o["inScatteringStart"])
    return o


def uniforms(params, camera, light_dir=None):
    """What prepareFog (and prepareDirectionalLight / prepareAmbientLight) put in frameUniforms."""
    o = set_fog_options(params)
    e = dict(ENGINE_DEFAULTS, **{k: v for k, v in params.items() if k in ENGINE_DEFAULTS})
    cam_y = camera[1]  # userCameraPosition.y, fog space = world space
    falloff = f32(max(0.0, o["heightFalloff"]))
    # -falloff * (camera height above the fog floor): the exponent of the density at the camera
    y = f32(-(falloff * (cam_y - f32(o["height"]))))
    density = f32(o["density"])
    u = {
        "fogStart": f32(o["distance"]),
        "fogMaxOpacity": f32(o["maximumOpacity"]),
        "fogHeightFalloff": falloff,
        "fogCutOffDistance": f32(o["cutOffDistance"]),
        "fogColor": tuple(f32(c) for c in o["color"]),
        "fogDensity": (density, y, f32(density * f32(_exp(y)))),
        "fogInscatteringStart": f32(o["inScatteringStart"]),
        "fogInscatteringSize": f32(o["inScatteringSize"]),
        "iblLuminance": f32(e["iblLuminance"]),
    }
    # Linear fog: slope k of the opacity in [1/m], from the same options (PR #9030).
    eye = cam_y - o["height"]
    if falloff <= FLT_EPSILON:
        k = o["density"] * 1.0
    else:
        num = _exp(-falloff * eye) - _exp(-2.0 * falloff * eye)
        den = falloff * eye
        k = o["density"] * (num / den if den != 0.0 else math.nan)  # 0/0 when the camera is at `height`
    u["fogLinearParams"] = (f32(k), f32(-k * o["distance"]))
    # Fog colour from a texture: skyColor wins, else the IBL's reflections when fogColorFromIbl.
    sampler = e["iblSample"]
    levels = float(e["iblLevels"])
    u["fogColorFromIbl"] = 0.0
    if sampler is not None and o["skyColor"]:
        u["fogColorFromIbl"], u["fogMinMaxMip"] = 1.0, (0.0, levels - 1.0)
    elif sampler is not None and o["fogColorFromIbl"]:
        u["fogColorFromIbl"], u["fogMinMaxMip"] = 1.0, (levels - 2.0, levels - 1.0)
    near, far = e["cameraNear"], e["cameraFar"]
    u["fogOneOverFarMinusNear"] = f32(1.0 / (far - near))
    u["fogNearOverFarMinusNear"] = f32(near / (far - near))
    # The directional light (prepareDirectionalLight): towards the light, normalised.
    if light_dir is not None:
        n = math.sqrt(_dot(light_dir, light_dir))
        u["lightDirection"] = tuple(f32(x / n) for x in light_dir)
        u["lightColorIntensity"] = tuple(f32(c) for c in e["lightColor"]) + (f32(e["lightIntensity"]),)
    else:
        u["lightDirection"] = (0.0, 0.0, 0.0)
        u["lightColorIntensity"] = (0.0, 0.0, 0.0, 0.0)
    return u, e


def _ibl_tint(u, e, view, d, linear):
    if u["fogColorFromIbl"] <= 0.0:
        return (1.0, 1.0, 1.0)
    lo, hi = u["fogMinMaxMip"]
    if linear:
        lod = lo
    else:
        depth = d * u["fogOneOverFarMinusNear"] - u["fogNearOverFarMinusNear"]
        t = min(max(depth, 0.0), 1.0)
        lod = hi + (lo - hi) * t  # mix(max, min, depth): far away samples the sharper level
    return e["iblSample"](view, lod)


def _blend(e, rgb):
    mode = e["blendMode"]
    if mode == "transparent":
        return tuple(c * e["alpha"] for c in rgb)
    if mode == "add":
        return (0.0, 0.0, 0.0)
    return rgb  # opaque, masked; multiply and screen are left as they are (FIXMEs in the shader)


def fragment(u, e, view):
    """surface_fog.fs fog(): (opacity, fog_rgb, sun_rgb) for the fog-space vector camera -> point."""
    d = math.sqrt(_dot(view, view))
    none = (0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    if d < u["fogStart"]:
        return none
    if d > u["fogCutOffDistance"]:
        return none
    dx, dy, dz = u["fogDensity"]
    falloff = u["fogHeightFalloff"]
    mean = dz  # optical path per metre: density at the camera ...
    fh = falloff * view[1]
    if abs(fh) > NEAR_LEVEL:  # ... or its mean over the whole ray [0, d]
        mean = (dz - dx * _exp(dy - fh)) / fh
    path = mean * max(d - u["fogStart"], 0.0)
    transmittance = _exp(-path)
    opacity = min(1.0 - transmittance, u["fogMaxOpacity"])
    tint = _ibl_tint(u, e, view, d, linear=False)
    fog_rgb = tuple(c * t * u["iblLuminance"] * opacity for c, t in zip(u["fogColor"], tint))
    sun = (0.0, 0.0, 0.0)
    size = u["fogInscatteringSize"]
    if size > 0.0:
        sun_path = mean * max(d - u["fogInscatteringStart"], 0.0)
        sun_transmittance = _exp(-sun_path)
        rgb, w = u["lightColorIntensity"][:3], u["lightColorIntensity"][3]
        amount = max(_dot(view, u["lightDirection"]) / d, 0.0) if d > 0.0 else 0.0  # GLSL: undefined at d = 0
        lobe = amount ** size
        sun = tuple(c * w * (lobe * (1.0 - sun_transmittance)) for c in rgb)
    return opacity, _blend(e, fog_rgb), _blend(e, sun)


def fragment_linear(u, e, view):
    """surface_fog.fs fogLinear()."""
    d = math.sqrt(_dot(view, view))
    none = (0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    if d < u["fogStart"] or d > u["fogCutOffDistance"]:
        return none
    a, b = u["fogLinearParams"]
    x = a * d + b
    opacity = x if math.isnan(x) else min(max(x, 0.0), 1.0)  # saturate(); NaN passes through here
    tint = _ibl_tint(u, e, view, d, linear=True)
    fog_rgb = tuple(c * t * u["iblLuminance"] * opacity for c, t in zip(u["fogColor"], tint))
    return opacity, _blend(e, fog_rgb), (0.0, 0.0, 0.0)


def fog(params, camera, point, light_dir=None):
    """(opacity, fog_rgb, sun_rgb) as Filament computes them for one fragment; Filament's colour
    is object * (1 - opacity) + fog_rgb + sun_rgb. `camera`, `point`: world positions in metres,
    y up; `light_dir`: towards the directional light (None: there is none)."""
    if not params.get("enabled", DEFAULTS["enabled"]):
        return 0.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    u, e = uniforms(params, camera, light_dir)
    view = _sub(point, camera)
    if e["linearFog"]:
        return fragment_linear(u, e, view)
    return fragment(u, e, view)


def to_effectd(params, light_dir=None):
    """The effectd Fog (wire names) that reproduces this Filament fog wherever effectd and
    Filament agree (see F1-F8 above for where they do not)."""
    o = set_fog_options(params)
    e = dict(ENGINE_DEFAULTS, **{k: v for k, v in params.items() if k in ENGINE_DEFAULTS})
    out = {
        "fogType": "HEIGHT",
        "color": [c * e["iblLuminance"] for c in o["color"]],
        "density": o["density"],
        "heightFalloff": o["heightFalloff"],
        "baseHeight": o["height"],
        "startDistance": o["distance"],
        "maxOpacity": o["maximumOpacity"],
    }
    if not math.isinf(o["cutOffDistance"]):
        out["cutoffDistance"] = o["cutOffDistance"]
    if o["inScatteringSize"] > 0.0 and light_dir is not None:
        out["directional"] = {
            "color": [c * e["lightIntensity"] for c in e["lightColor"]],
            "direction": list(light_dir),
            "exponent": o["inScatteringSize"],
            "startDistance": o["inScatteringStart"],
        }
    return out
