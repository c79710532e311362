"""Unreal Engine's ExponentialHeightFog, one pixel at a time: an independent transcription of the
maths of Epic's shader and setup code into Python (standard library only). Nothing here is
Epic's code; it is the same arithmetic, written out, so that effectd's C++ can be tested
against it.

Sources read. Epic's own repository (github.com/EpicGames/UnrealEngine) is private; the stored
index holds unofficial copies of it, and these were read (UE 5.8.0 per Engine/Build/Build.version):
  repository unicorn2022/UE5.8.0 @ 5d9a05c15b1f8c6d7b3354b360677ce30d688149
  * Engine/Shaders/Private/HeightFogCommon.ush (index id 54502895163):
      CalculateLineIntegralShared()  (chars ~11 900-12 400)
      GetExponentialHeightFog()      (chars ~13 000-21 600): observer clamp, EndDistance,
                                     StartDistance, both layers, directional in-scattering,
                                     MinFogOpacity, FogCutoffDistance, the returned (colour, f)
      CalculateHeightFog()           (ExcludeDistance from volumetric fog)
  * Engine/Source/Runtime/Renderer/Private/FogRendering.cpp (id 55038108287):
      FSceneRenderer::InitFogConstants() (chars ~16 600-21 900): collapsed densities, observer
      height clamp, the packed uniform vectors, sun direction and colour;
      SetupFogUniformParameters(): 1 - FogMaxOpacity, start clamp, exponent clamp, EndDistance;
      RenderViewFog(): the blend (dst = src.rgb + dst * src.a)
  * Engine/Source/Runtime/Renderer/Private/SceneCore.cpp (id 55039553036),
      FExponentialHeightFogSceneInfo::FExponentialHeightFogSceneInfo: /1000 scalings, heights
  * Engine/Source/Runtime/Engine/Private/Components/ExponentialHeightFogComponent.cpp:
      the constructor (defaults), AddFogIfNeeded (when the fog exists), PostEditChangeProperty
  * Engine/Source/Runtime/Engine/Classes/Components/ExponentialHeightFogComponent.h (property docs)
  and for comparison: Nuika/Light-Unreal-Engine-5.3 @ f9d20e64 HeightFogCommon.ush (UE 5.3, with
  local edits marked "Custom"; its GetExponentialHeightFog has no EndDistance, otherwise the same
  maths); chenyong2github/UnrealEngine @ 01b8645f ExponentialHeightFogComponent.h (the struct
  FExponentialHeightFogData with defaults 0.02 / 0.2 / 0 and ClampToValidRanges [0,10] / [0,2]);
  Epic's docs "Exponential Height Fog in Unreal Engine" (dev.epicgames.com) for the property
  descriptions, and the Python API page for ExponentialHeightFogData (defaults 0.02, 0.2, 0.0).
  Line numbers: the index reports character offsets only; the functions are named above.
Everything below is from the shader and C++ text except where marked (docs).

Parameters (`params`, the component's property names; world units are centimetres, Z is up):
  FogDensity        0.02   global density factor; the renderer uses FogDensity / 1000 [1/cm]
  FogHeightFalloff  0.2    the renderer uses FogHeightFalloff / 1000 [1/cm]
  FogHeight         0      the component's world Z [cm] (GetComponentLocation().Z)
  SecondFogData     {FogDensity 0 (set by the component), FogHeightFalloff 0.2, FogHeightOffset 0}
                    second layer, height FogHeight + FogHeightOffset; clamped [0,10] / [0,2]
  FogInscatteringLuminance (0,0,0)  "Fog Inscattering Color" (5.8 default black; UE 4 default
                    (0.447, 0.638, 1.0) as FogInscatteringColor)
  FogMaxOpacity     1      f >= 1 - FogMaxOpacity
  StartDistance     0      [cm]
  EndDistance       0      [cm], 0 = off: horizontal (XY) distance past which the ray is shortened
  FogCutoffDistance 0      [cm], 0 = off: beyond it, no fog
  DirectionalInscatteringExponent      4      lobe max(cos, 0)^n (clamped to [1e-6, 1000])
  DirectionalInscatteringStartDistance 10000  [cm] (clamped >= 0)
  DirectionalInscatteringLuminance     (0,0,0) "Directional Inscattering Color" (5.8 default
                    black; UE 4 default (0.25, 0.25, 0.125))
Engine inputs that are not component properties:
  SunLightColor   (1,1,1)  the atmosphere sun light's colour * intensity; only its luminance
                           0.3 R + 0.59 G + 0.11 B (FLinearColor::GetLuminance) is used
  ExcludeDistance 0        the analytical fog's start from volumetric fog
                           (VolumetricFogMaxDistance / cos(angle to the view axis)); 0 = none
  SimpleFog       False    mobile r.Mobile.PixelFogQuality 0: no second layer, no directional
Not transcribed (each an engine feature effectd does not have): the inscattering cubemap, sky
atmosphere and sky-light-capture contributions, planar-reflection clip planes, orthographic
height adjustment, PROJECT_EXPFOG_MATCHES_VFOG, holdout, volumetric fog itself.

fog(params, camera, point, light_dir) returns (f, fog_rgb, inscatter_rgb) for the pixel at
`point` seen from `camera` (both in cm, Z up); light_dir points towards the sun
(-SunLight->Proxy->GetDirection()), None = no sun light (directional in-scattering off).
Unreal writes colour = scene * f + fog_rgb + inscatter_rgb (the fog pass blends One, SourceAlpha).
Uniforms are rounded to float32 (FVector4f); the shader arithmetic is done in double.

The maths. a_i = FogDensity_i/1000, b_i = FogHeightFalloff_i/1000, h_i the layer heights,
v = p - c, L = |v| (after the clamps below), s = max(StartDistance, ExcludeDistance):
    z_o = min(c_z, min over layers with a_i > 0 of (h_i + 65536))       (observer clamp)
    v_z += c_z - z_o; the ray starts at height z_o
    R_i = a_i 2^(-b_i (z_s - h_i)), z_s the height at distance s along the ray (z_o when s = 0)
    F_i = max(-127, b_i dz), dz the rise of the ray over [s, L]
    I_i = R_i (1 - 2^-F_i) / F_i   if |F_i| > 0.01, else R_i (ln2 - ln2^2 F_i / 2)
    f   = max(saturate(2^(-(I_1 + I_2) (L - s))), 1 - FogMaxOpacity);  f = 1 if 0 < cutoff < L
    fog_rgb = FogInscatteringLuminance * (1 - f)
    inscatter_rgb = DirectionalInscatteringLuminance * lum(SunLightColor) * max(dot(v/L, l), 0)^n
                    * (1 - saturate(2^(-(I_1 + I_2) max(L - s - s_dir, 0))))   (0 past the cutoff)
Because 2^-x = e^(-x ln2) and (1 - 2^-F)/F = ln2 (1 - e^(-F ln2))/(F ln2), this IS the exact
exponential height fog  f = e^(-tau),  tau = integral over [s, L] of sigma,  with
    sigma(z) = A e^(-B (z - h)),   A = ln(2)^2 * FogDensity / 1000,  B = ln(2) * FogHeightFalloff / 1000
(per cm). In metres: A = 0.1 ln(2)^2 FogDensity = 0.048045 FogDensity [1/m],
B = 0.1 ln(2) FogHeightFalloff = 0.069315 FogHeightFalloff [1/m], heights / 100.

Mapping to effectd's Fog (effects/include/effects/fog.h; wire names of server/api/api_fog.cpp),
with y_effectd = Z / 100 and lengths / 100 (see to_effectd()):
  fogType HEIGHT; density <- A; heightFalloff <- B; baseHeight <- FogHeight / 100;
  secondLayer <- {A_2, B_2, (FogHeight + FogHeightOffset) / 100} (when its density > 0);
  startDistance <- StartDistance / 100; maxOpacity <- FogMaxOpacity;
  cutoffDistance <- FogCutoffDistance / 100 (absent when 0); color <- FogInscatteringLuminance;
  directional <- {exponent n, color DirectionalInscatteringLuminance * lum(sun),
  direction l (Y and Z swapped), startDistance (StartDistance + s_dir) / 100}.

Where Unreal differs from effectd's exact integral (effectd at cea8743):
  U1 units: exp2 in the shader and the /1000 scalings: the ln2^2 and ln2 factors above, cm, Z up.
     With them, the main fog (both layers, StartDistance, cap, cutoff) equals effectd's exact
     closed form, except U2-U5.
  U2 near-level guard: |F| <= 0.01 (F = b dz in log2 units) uses the first-order Taylor
     ln2 - ln2^2 F / 2 (relative error in tau below ~6e-6); effectd is exact.
  U3 exponent clamps: F >= -127 (steep descents through dense fog get less fog), the collapsed
     density's exponent in [-125, 126], the start point's exponent >= -127.
  U4 observer height: the camera is moved down to 65536 cm (655.36 m) above the LOWEST floor
     among the layers that have density (min of h_i + 65536); the ray then starts there (the
     point stays where it is), so it is longer and starts lower.
  U5 EndDistance (5.x): when the XY distance exceeds EndDistance the whole vector camera->point
     is scaled by EndDistance / |v_xy|: fog, glow and the cutoff test all see the shortened ray.
  U6 directional start: the glow's ray starts at StartDistance + DirectionalInscatteringStartDistance
     (a sum); effectd uses max(startDistance, directional.startDistance).
  U7 directional weight: 1 - e^(-tau[s, L] * max(L - s - s_dir, 0) / (L - s)): the mean density of
     the fogged part times the glow's length, not the exact integral over [s + s_dir, L]; NOT
     capped by FogMaxOpacity (effectd caps it); zero past the cutoff (as effectd); off without a
     sun light, with an inscattering cubemap, or on SimpleFog.
  U8 directional colour: DirectionalInscatteringLuminance * luminance(sun colour * intensity);
     effectd's directional.color is that product, given directly.
  U9 the fog colour may exceed 1 (a luminance); effectd validates color in [0, 1].
  U10 half precision: the shader returns half4 (colour and f rounded to fp16 on the way out).
  Same as effectd: the cap (f >= 1 - FogMaxOpacity), the fog colour weight (1 - f), the strict
  cutoff (L > cutoff), the exact integral over [StartDistance, L] with two layers.
"""
import math

from floats import f32

INF = math.inf
FLT_MAX = 3.4028234663852886e38
LN2 = math.log(2.0)
UE_DELTA = 0.00001
MAX_OBSERVER_HEIGHT_DIFFERENCE = 65536.0  # cm
TAYLOR_BELOW = 0.01  # FLT_EPSILON2 in HeightFogCommon.ush

DEFAULTS = {
    "FogDensity": 0.02, "FogHeightFalloff": 0.2, "FogHeight": 0.0,
    "SecondFogData": {"FogDensity": 0.0, "FogHeightFalloff": 0.2, "FogHeightOffset": 0.0},
    "FogInscatteringLuminance": (0.0, 0.0, 0.0), "FogMaxOpacity": 1.0, "StartDistance": 0.0,
    "EndDistance": 0.0, "FogCutoffDistance": 0.0, "DirectionalInscatteringExponent": 4.0,
    "DirectionalInscatteringStartDistance": 10000.0,
    "DirectionalInscatteringLuminance": (0.0, 0.0, 0.0),
}
ENGINE_DEFAULTS = {"SunLightColor": (1.0, 1.0, 1.0), "ExcludeDistance": 0.0, "SimpleFog": False}


def _exp2(x):
    try:
        return 2.0 ** x
    except OverflowError:
        return INF


def _saturate(x):
    return min(max(x, 0.0), 1.0)


def luminance(rgb):
    """FLinearColor::GetLuminance."""
    return rgb[0] * 0.3 + rgb[1] * 0.59 + rgb[2] * 0.11


def _options(params):
    o = dict(DEFAULTS, **{k: v for k, v in params.items() if k in DEFAULTS})
    second = dict(DEFAULTS["SecondFogData"], **params.get("SecondFogData", {}))
    # FExponentialHeightFogData::ClampToValidRanges (AddFogIfNeeded)
    second["FogDensity"] = min(max(second["FogDensity"], 0.0), 10.0)
    second["FogHeightFalloff"] = min(max(second["FogHeightFalloff"], 0.0), 2.0)
    o["SecondFogData"] = second
    e = dict(ENGINE_DEFAULTS, **{k: v for k, v in params.items() if k in ENGINE_DEFAULTS})
    return o, e


def exists(params):
    """AddFogIfNeeded: the fog is in the scene only with some density and some opacity."""
    o, _ = _options(params)
    return (o["FogDensity"] + o["SecondFogData"]["FogDensity"]) * 1000 > UE_DELTA and o["FogMaxOpacity"] > UE_DELTA


def uniforms(params, camera, light_dir=None):
    """FogStruct as FExponentialHeightFogSceneInfo, InitFogConstants and
    SetupFogUniformParameters fill it (perspective view, no cubemap)."""
    o, e = _options(params)
    second = o["SecondFogData"]
    height = [f32(o["FogHeight"]), f32(o["FogHeight"] + second["FogHeightOffset"])]
    density = [f32(o["FogDensity"] / 1000.0), f32(second["FogDensity"] / 1000.0)]
    falloff = [f32(o["FogHeightFalloff"] / 1000.0), f32(second["FogHeightFalloff"] / 1000.0)]
    max_observer = FLT_MAX
    for i in range(2):
        if density[i] > 0.0:
            max_observer = min(max_observer, height[i] + MAX_OBSERVER_HEIGHT_DIFFERENCE)
    observer = min(camera[2], max_observer)
    collapsed = []
    for i in range(2):
        power = min(max(-falloff[i] * (observer - height[i]), -126.0 + 1.0), 127.0 - 1.0)
        collapsed.append(f32(density[i] * 2.0 ** power))
    simple = bool(e["SimpleFog"])
    u = {
        "ExponentialFogParameters": (collapsed[0], falloff[0], f32(max_observer), f32(o["StartDistance"])),
        "ExponentialFogParameters2": (0.0, 0.0, 0.0, 0.0) if simple else (collapsed[1], falloff[1], density[1], height[1]),
        "ExponentialFogColorParameter": tuple(f32(c) for c in o["FogInscatteringLuminance"]) + (f32(1.0 - o["FogMaxOpacity"]),),
        "ExponentialFogParameters3": (density[0], height[0], 0.0, f32(o["FogCutoffDistance"])),
        "EndDistance": f32(o["EndDistance"]),
        "SecondTerm": not simple,
    }
    use_directional = light_dir is not None and not simple
    if light_dir is not None:
        n = math.sqrt(sum(x * x for x in light_dir))
        direction = tuple(f32(x / n) for x in light_dir)
        sun = luminance(e["SunLightColor"])
        color = tuple(f32(c * sun) for c in o["DirectionalInscatteringLuminance"])
    else:
        direction, color = (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    start = max(0.0, o["DirectionalInscatteringStartDistance"]) if use_directional else -1.0
    u["InscatteringLightDirection"] = direction + (f32(start),)
    u["DirectionalInscatteringColor"] = color + (f32(min(max(o["DirectionalInscatteringExponent"], 0.000001), 1000.0)),)
    return u, e


def line_integral_shared(falloff, ray_direction_z, ray_origin_terms):
    """CalculateLineIntegralShared: density at the ray's start times (1 - 2^-F)/F, F = falloff * rise."""
    f = max(-127.0, falloff * ray_direction_z)
    if abs(f) > TAYLOR_BELOW:
        return ray_origin_terms * (1.0 - _exp2(-f)) / f
    return ray_origin_terms * (LN2 - 0.5 * LN2 * LN2 * f)


def pixel(u, camera, relative, exclude_distance=0.0):
    """GetExponentialHeightFog(WorldPositionRelativeToCamera, ExcludeDistance): (f, fog_rgb,
    inscatter_rgb)."""
    p1, p2, p3 = u["ExponentialFogParameters"], u["ExponentialFogParameters2"], u["ExponentialFogParameters3"]
    color = u["ExponentialFogColorParameter"]
    min_fog_opacity = color[3]
    observer_z = min(camera[2], p1[2])
    v = list(relative)
    end = u["EndDistance"]
    xy2 = v[0] * v[0] + v[1] * v[1]
    if end > 0.0 and xy2 > end * end:
        scale = end / math.sqrt(max(1.0, xy2))
        v = [x * scale for x in v]
    v[2] += camera[2] - observer_z
    length2 = v[0] * v[0] + v[1] * v[1] + v[2] * v[2]
    inv = 1.0 / math.sqrt(max(length2, 0.00000001))
    length = length2 * inv
    normal = [x * inv for x in v]

    origin_terms, origin_terms2 = p1[0], p2[0]
    ray_length, ray_z = length, v[2]
    exclude = max(exclude_distance, p1[3])
    if exclude > 0.0:
        t = exclude * inv
        rise_to_start = t * v[2]
        start_z = observer_z + rise_to_start
        ray_length = (1.0 - t) * length  # negative when the point is nearer than the start
        ray_z = v[2] - rise_to_start
        origin_terms = p3[0] * _exp2(-max(-127.0, p1[1] * (start_z - p3[1])))
        origin_terms2 = p2[2] * _exp2(-max(-127.0, p2[1] * (start_z - p2[3])))

    shared = line_integral_shared(p1[1], ray_z, origin_terms)
    if u["SecondTerm"]:
        shared += line_integral_shared(p2[1], ray_z, origin_terms2)
    integral = shared * ray_length

    inscattering = color[:3]
    directional = (0.0, 0.0, 0.0)
    light = u["InscatteringLightDirection"]
    if light[3] >= 0.0:
        dir_color = u["DirectionalInscatteringColor"]
        cos_theta = _saturate(sum(n * l for n, l in zip(normal, light[:3])))
        lobe = cos_theta ** dir_color[3]
        dir_integral = shared * max(ray_length - light[3], 0.0)
        dir_factor = _saturate(_exp2(-dir_integral))
        directional = tuple(c * lobe * (1.0 - dir_factor) for c in dir_color[:3])

    f = max(_saturate(_exp2(-integral)), min_fog_opacity)
    if p3[3] > 0.0 and length > p3[3]:
        f = 1.0
        directional = (0.0, 0.0, 0.0)
    fog_rgb = tuple(c * (1.0 - f) for c in inscattering)
    return f, fog_rgb, directional


def fog(params, camera, point, light_dir=None):
    """(f, fog_rgb, inscatter_rgb) as Unreal computes them for one pixel; Unreal's colour is
    scene * f + fog_rgb + inscatter_rgb. `camera`, `point`: world positions in cm, Z up;
    `light_dir`: towards the sun (None: no atmosphere sun light)."""
    if not exists(params):
        return 1.0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)
    u, e = uniforms(params, camera, light_dir)
    relative = tuple(p - c for p, c in zip(point, camera))
    return pixel(u, camera, relative, e["ExcludeDistance"])


def density_per_metre(fog_density, metres_per_unit=0.01):
    """effectd's a [1/m] for an Unreal FogDensity: ln2^2 FogDensity / 1000 per world unit."""
    return LN2 * LN2 * fog_density / 1000.0 / metres_per_unit


def falloff_per_metre(fog_height_falloff, metres_per_unit=0.01):
    """effectd's b [1/m] for an Unreal FogHeightFalloff: ln2 FogHeightFalloff / 1000 per unit."""
    return LN2 * fog_height_falloff / 1000.0 / metres_per_unit


def to_effectd_point(p, metres_per_unit=0.01):
    """Unreal (X, Y, Z up) in cm -> effectd (x, y up, z) in m. Handedness does not matter to fog."""
    return (p[0] * metres_per_unit, p[2] * metres_per_unit, p[1] * metres_per_unit)


def to_effectd(params, light_dir=None, metres_per_unit=0.01):
    """The effectd Fog (wire names) that reproduces this Unreal fog wherever effectd and Unreal
    agree (U1 folded in; see U2-U10 for where they do not)."""
    o, e = _options(params)
    k = metres_per_unit
    second = o["SecondFogData"]
    out = {
        "fogType": "HEIGHT",
        "color": list(o["FogInscatteringLuminance"]),
        "density": density_per_metre(o["FogDensity"], k),
        "heightFalloff": falloff_per_metre(o["FogHeightFalloff"], k),
        "baseHeight": o["FogHeight"] * k,
        "startDistance": o["StartDistance"] * k,
        "maxOpacity": o["FogMaxOpacity"],
    }
    if second["FogDensity"] > 0.0:
        out["secondLayer"] = {
            "density": density_per_metre(second["FogDensity"], k),
            "heightFalloff": falloff_per_metre(second["FogHeightFalloff"], k),
            "baseHeight": (o["FogHeight"] + second["FogHeightOffset"]) * k,
        }
    if o["FogCutoffDistance"] > 0.0:
        out["cutoffDistance"] = o["FogCutoffDistance"] * k
    if light_dir is not None and not e["SimpleFog"]:
        sun = luminance(e["SunLightColor"])
        out["directional"] = {
            "color": [c * sun for c in o["DirectionalInscatteringLuminance"]],
            "direction": list(to_effectd_point(light_dir, 1.0)),
            "exponent": min(max(o["DirectionalInscatteringExponent"], 0.000001), 1000.0),
            "startDistance": (o["StartDistance"] + max(0.0, o["DirectionalInscatteringStartDistance"])) * k,
        }
    return out
