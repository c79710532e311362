// The fog in a shader: the GLSL of a fog and its regions (the formulas of the fog types they
// use and nothing else: shaderVariant) and its uniforms' values for a camera. The renderer's
// passes (render/fog.cpp uploads the uniforms), /v1/fog's include "shader" and engines all
// take it from here. Its formulas are fog.cpp's, per fragment.
#include <algorithm>
#include <cmath>
#include <numeric>
#include <sstream>

#include <glm/geometric.hpp>
#include <glm/vec4.hpp>

#include "effects/fog.h"

namespace effects::fog {

namespace {

// A height layer as fogHeightTau reads it: (log a, b, h, a > 0).
glm::dvec4 heightLayerUniform(double a, double b, double h) {
  return {a > 0 ? std::log(a) : 0.0, b, h, a > 0 ? 1.0 : 0.0};
}

}  // namespace

// Slot 0 = global fog; slots 1.. = regions by increasing volume (stable: ties keep their
// order), so that the shader's first containing region is regionAt()'s choice.
std::vector<ShaderUniform> shaderUniforms(const Fog& global, const std::vector<Region>& regions, const glm::dvec3& eye) {
  std::vector<size_t> order(regions.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return fog::logVolume(regions[a]) < fog::logVolume(regions[b]); });
  const ShaderVariant variant = shaderVariant(global, regions);
  std::vector<double> types, params, colors, lo, hi, engine, layer2, sun, sunColor, inscatter;
  auto add = [&](const fog::Fog& g) {
    types.push_back(int(g.type));
    const double cutoff = std::isfinite(g.cutoffDistance) ? g.cutoffDistance : 0.0;
    for (double x : {g.startDistance, cutoff, 1.0 - g.maxOpacity, double(int(g.convention))}) engine.push_back(x);
    const fog::HeightLayer l = g.secondLayer.value_or(fog::HeightLayer{});
    const glm::dvec4 l2 = heightLayerUniform(l.density, l.heightFalloff, l.baseHeight);
    for (int i = 0; i < 4; ++i) layer2.push_back(l2[i]);
    const fog::Directional dir = g.directional.value_or(fog::Directional{});
    const glm::dvec3 toSun = glm::normalize(dir.direction);
    const glm::dvec3 glow = g.directional ? dir.color : glm::dvec3(0);
    // In float, g within 6e-8 of +-1 would round to +-1 (a lobe of 0/0): the shader's lobe
    // stops at |g| = 0.999999 (peak 2e12), where the double reference goes on.
    const double g32 = std::clamp(dir.g, -0.999999, 0.999999);
    for (double x : {toSun.x, toSun.y, toSun.z, dir.exponent ? 2.0 + *dir.exponent : g32}) sun.push_back(x);
    for (double x : {glow.r, glow.g, glow.b, dir.startDistance}) sunColor.push_back(x);
    glm::dvec4 q(0);
    switch (g.type) {
      case fog::FogType::kX3dLinear:
      case fog::FogType::kX3dExponential: q.x = g.visibilityRange; break;
      case fog::FogType::kGlLinear: q = {g.start, g.end, 0, 0}; break;
      case fog::FogType::kGlExp:
      case fog::FogType::kGlExp2: q.x = g.density; break;
      case fog::FogType::kDistanceExp2: q.x = g.distanceCoefficient; break;
      case fog::FogType::kDistanceGaussian: q = {g.distanceCoefficient, g.peak, 0, 0}; break;
      case fog::FogType::kHeight: q = heightLayerUniform(g.density, g.heightFalloff, g.baseHeight); break;
      case fog::FogType::kAtmospheric: q = glm::dvec4(g.extinction, 0); break;
    }
    for (int i = 0; i < 3; ++i) inscatter.push_back(g.type == fog::FogType::kAtmospheric ? g.inscattering[i] : 0.0);
    for (int i = 0; i < 4; ++i) params.push_back(q[i]);
    for (int i = 0; i < 3; ++i) colors.push_back(g.color[i]);
  };
  add(global);
  for (size_t i : order) {
    const fog::Region& r = regions[i];
    add(r.fog);
    glm::dvec4 a = r.shape == fog::Region::Shape::kBox ? glm::dvec4(r.min, 0) : glm::dvec4(r.center, 1);
    glm::dvec4 b = r.shape == fog::Region::Shape::kBox ? glm::dvec4(r.max, 0) : glm::dvec4(r.radius, 0, 0, 0);
    for (int k = 0; k < 4; ++k) lo.push_back(a[k]), hi.push_back(b[k]);
  }
  const std::string slots = "[" + std::to_string(types.size()) + "]",
                    regionSlots = "[" + std::to_string(order.size()) + "]";
  std::vector<ShaderUniform> out = {{"uFogCamera", "vec3", {eye.x, eye.y, eye.z}},
                                         {"uFogType", "int" + slots, types},
                                         {"uFogParams", "vec4" + slots, params},
                                         {"uFogColor", "vec3" + slots, colors}};
  if (variant.engine()) out.push_back({"uFogEngine", "vec4" + slots, engine});
  if (variant.secondLayer) out.push_back({"uFogLayer2", "vec4" + slots, layer2});
  if (std::count(variant.types.begin(), variant.types.end(), fog::FogType::kAtmospheric))
    out.push_back({"uFogInscatter", "vec3" + slots, inscatter});
  if (variant.directional) {
    out.push_back({"uFogSun", "vec4" + slots, sun});
    out.push_back({"uFogSunColor", "vec4" + slots, sunColor});
  }
  if (!order.empty()) {
    out.push_back({"uRegionLo", "vec4" + regionSlots, lo});
    out.push_back({"uRegionHi", "vec4" + regionSlots, hi});
  }
  return out;
}


std::string ShaderVariant::key() const {
  std::string k = "fog";
  for (fog::FogType t : types) k += std::string(":") + fog::toString(t);
  k += ":r" + std::to_string(regions);
  if (start) k += ":start";
  if (cutoff) k += ":cutoff";
  if (opacity) k += ":maxOpacity";
  if (secondLayer) k += ":secondLayer";
  if (directional) k += ":directional";
  if (filament) k += ":filament";
  if (unreal) k += ":unreal";
  return k;
}

ShaderVariant shaderVariant(const Fog& global, const std::vector<Region>& regions) {
  ShaderVariant v;
  auto add = [&v](const fog::Fog& g) {
    v.types.push_back(g.type);
    v.start |= g.startDistance > 0.0;
    v.cutoff |= std::isfinite(g.cutoffDistance);
    v.opacity |= g.maxOpacity < 1.0;
    v.secondLayer |= g.secondLayer.has_value();
    v.directional |= g.directional.has_value();
    v.filament |= g.convention == fog::Convention::kFilament;
    v.unreal |= g.convention == fog::Convention::kUnreal;
  };
  add(global);
  for (const auto& r : regions) add(r.fog);
  std::sort(v.types.begin(), v.types.end());
  v.types.erase(std::unique(v.types.begin(), v.types.end()), v.types.end());
  v.regions = regions.size();
  return v;
}

namespace {

// HEIGHT fog in the engines' conventions (effects/fog/conventions.cpp, term for term): the
// fogged colour with its glow, per slot.
std::string engineConventionsGlsl(const ShaderVariant& v) {
  std::ostringstream s;
  const std::string glowStart =
      "  vec4 sun = uFogSun[slot], sc = uFogSunColor[slot];\n"
      "  float c = d > 0.0 ? clamp(dot(ray / d, sun.xyz), -1.0, 1.0) : 0.0;\n"
      "  float lobe = c > 0.0 ? pow(c, sun.w - 2.0) : 0.0;\n";
  if (v.filament) {
    s << "vec3 fogFilament(int slot, vec3 world, vec3 rgb) {  // Filament's surface fog\n"
         "  vec4 q = uFogParams[slot], e = uFogEngine[slot];\n"
         "  vec3 ray = world - uFogCamera;\n  float d = length(ray);\n"
         "  if (q.w < 0.5 || d < e.x || (e.y > 0.0 && d > e.y)) return rgb;\n"
         "  float fh = q.y * ray.y;  // the mean density over [0, d], or the camera's near level\n"
         "  float mean = exp(min(q.x - q.y * (uFogCamera.y - q.z) + (abs(fh) > 0.00125 ? fogLogG(fh) : 0.0), 80.0));\n"
         "  vec3 c0 = mix(uFogColor[slot], rgb, max(exp(-mean * max(d - e.x, 0.0)), e.z));\n";
    if (v.directional)
      s << glowStart
        << "  if (dot(sc.rgb, sc.rgb) > 0.0) c0 += (1.0 - exp(-mean * max(d - sc.w, 0.0))) * sc.rgb * lobe;\n";
    s << "  return c0;\n}\n";
  }
  if (v.unreal) {
    s << "float fogUnrealLine(float falloff, float rise, float origin) {  // CalculateLineIntegralShared\n"
         "  float f = max(-127.0, falloff * rise);\n"
         "  return abs(f) > 0.01 ? origin * (1.0 - exp2(-f)) / f : origin * (0.6931472 - 0.2402265 * f);\n"
         "}\n"
         "vec3 fogUnreal(int slot, vec3 world, vec3 rgb) {  // Unreal's ExponentialHeightFog, base 2\n"
         "  vec4 e = uFogEngine[slot];\n"
         "  vec4 q[2];\n  q[0] = uFogParams[slot];\n"
      << (v.secondLayer ? "  q[1] = uFogLayer2[slot];\n" : "  q[1] = vec4(0.0);\n")
      << "  float density[2], falloff[2];\n"
         "  float observer = uFogCamera.y;\n"
         "  for (int i = 0; i < 2; ++i) {\n"
         "    density[i] = q[i].w > 0.5 ? exp(q[i].x) / 0.480453 : 0.0;  // a / ln2^2\n"
         "    falloff[i] = q[i].y / 0.6931472;\n"
         "    if (density[i] > 0.0) observer = min(observer, q[i].z + 65536.0);\n"
         "  }\n"
         "  vec3 v = world - uFogCamera;\n  v.y += uFogCamera.y - observer;\n"
         "  float d = length(v), rayLength = d, rise = v.y;\n"
         "  float origin[2];\n"
         "  for (int i = 0; i < 2; ++i) origin[i] = density[i] * exp2(clamp(-falloff[i] * (observer - q[i].z), -125.0, "
         "126.0));\n"
         "  if (e.x > 0.0 && d > 0.0) {  // the ray from the start distance on\n"
         "    float t = e.x / d;\n    float startY = observer + t * v.y;\n"
         "    rayLength = (1.0 - t) * d;\n    rise = v.y - t * v.y;\n"
         "    for (int i = 0; i < 2; ++i) origin[i] = density[i] * exp2(-max(-127.0, falloff[i] * (startY - "
         "q[i].z)));\n"
         "  }\n"
         "  float perUnit = fogUnrealLine(falloff[0], rise, origin[0]) + fogUnrealLine(falloff[1], rise, origin[1]);\n"
         "  if (e.y > 0.0 && d > e.y) return rgb;\n"
         "  vec3 c0 = mix(uFogColor[slot], rgb, max(clamp(exp2(-perUnit * rayLength), 0.0, 1.0), e.z));\n";
    if (v.directional)
      s << "  vec3 ray = v;\n"
        << glowStart
        << "  if (dot(sc.rgb, sc.rgb) > 0.0)\n"
           "    c0 += (1.0 - clamp(exp2(-perUnit * max(rayLength - sc.w, 0.0)), 0.0, 1.0)) * sc.rgb * lobe;\n";
    s << "  return c0;\n}\n";
  }
  return s.str();
}

}  // namespace

// Long because it is one GLSL program read top to bottom: uniforms, each fog type's function,
// the engine terms, then applyFog; each piece is emitted only for the variant that uses it.
std::string shaderGlsl(const ShaderVariant& v) {
  using T = fog::FogType;
  auto has = [&](T t) { return std::find(v.types.begin(), v.types.end(), t) != v.types.end(); };
  const size_t slots = v.regions + 1;
  std::ostringstream s;
  s << "// fog: " << v.key() << " (effects::fog::factor, per fragment)\n"
    << "uniform vec3 uFogCamera;\n"
    << "uniform int uFogType[" << slots << "];\n"
    << "uniform vec4 uFogParams[" << slots << "];\n"
    << "uniform vec3 uFogColor[" << slots << "];\n";
  if (v.regions)
    s << "uniform vec4 uRegionLo[" << v.regions << "];  // box min | sphere centre; w: 0 box, 1 sphere\n"
      << "uniform vec4 uRegionHi[" << v.regions << "];  // box max | x = sphere radius\n";
  if (v.engine())
    s << "uniform vec4 uFogEngine[" << slots << "];  // startDistance, cutoffDistance (0: none), 1 - maxOpacity"
      << (v.filament || v.unreal ? ", convention (0 effectd, 1 filament, 2 unreal)" : "") << "\n";
  if (v.secondLayer) s << "uniform vec4 uFogLayer2[" << slots << "];  // HEIGHT's second layer: log a, b, h, a > 0\n";
  if (has(T::kAtmospheric))
    s << "uniform vec3 uFogInscatter[" << slots << "];  // ATMOSPHERIC: inscattering per channel\n";
  if (v.directional)
    s << "uniform vec4 uFogSun[" << slots
      << "];       // unit direction to the sun; w: HG g in (-1, 1), or 2 + exponent\n"
      << "uniform vec4 uFogSunColor[" << slots
      << "];  // rgb (0: no glow in this slot); w: the glow's start distance\n";
  // With a start distance (the fog's or the glow's) the mode is evaluated over the ray's part
  // [s, d], s a parameter; with that or a second layer, height fog sums layers along it
  // (fogHeightTau); otherwise the one-layer form below it.
  const bool startParam = v.start || v.directional;
  const bool layered = startParam || v.secondLayer;
  if (has(T::kHeight) || v.filament)
    s << "float fogLogG(float x) {  // log((1 - e^-x) / x), stable for every x\n"
         "  if (abs(x) < 1e-3) return -0.5 * x + x * x / 24.0;\n"
         "  if (x > 0.0) return log(1.0 - exp(-x)) - log(x);\n"
         "  if (x > -80.0) return log(exp(-x) - 1.0) - log(-x);\n"
         "  return -x - log(-x);\n"
         "}\n";
  if (has(T::kHeight) && layered)
    s << "float fogHeightTau(vec4 q, float y0, float dirY, float t) {  // one layer over [0, t] from height y0\n"
         "  if (q.w < 0.5 || t == 0.0) return 0.0;\n"
         "  if (q.y == 0.0) return exp(min(q.x + log(t), 80.0));\n"
         "  return exp(min(q.x - q.y * (y0 - q.z) + log(t) + fogLogG(q.y * dirY * t), 80.0));\n"
         "}\n";
  s << (startParam ? "float fogMode(int slot, vec3 ray, float d, float start) {\n"
        : v.engine()
            ? "float fogMode(int slot, vec3 ray, float d) {\n"
            : "float fogFactor(int slot, vec3 world) {\n  vec3 ray = world - uFogCamera;\n  float d = length(ray);\n")
    << "  vec4 q = uFogParams[slot];\n  int type = uFogType[slot];\n";
  if (layered)
    s << "  float dirY = d > 0.0 ? ray.y / d : 0.0;\n"
      << (startParam ? "  float s = min(start, d);\n  float y0 = uFogCamera.y + dirY * s;\n  d -= s;\n"
                     : "  float y0 = uFogCamera.y;\n");
  for (T t : v.types) {
    s << "  if (type == " << int(t) << ") {  // " << fog::toString(t) << "\n";
    switch (t) {
      case T::kX3dLinear: s << "    return q.x <= 0.0 ? 1.0 : (d >= q.x ? 0.0 : (q.x - d) / q.x);\n"; break;
      case T::kX3dExponential: s << "    return q.x <= 0.0 ? 1.0 : (d >= q.x ? 0.0 : exp(-d / (q.x - d)));\n"; break;
      case T::kGlLinear: s << "    return clamp((q.y - d) / (q.y - q.x), 0.0, 1.0);\n"; break;
      case T::kGlExp: s << "    return exp(-q.x * d);\n"; break;
      case T::kGlExp2: s << "    return exp(-(q.x * d) * (q.x * d));\n"; break;
      case T::kDistanceExp2: s << "    return exp(-q.x * d * d);  // seed 003 eqn 1\n"; break;
      case T::kDistanceGaussian: s << "    return q.y * exp(-q.x * d * d);  // seed 003 eqn 2\n"; break;
      case T::kAtmospheric: s << "    return dot(exp(-q.xyz * d), vec3(1.0 / 3.0));  // the channels' mean\n"; break;
      case T::kHeight:
        if (layered) {
          s << "    float tau = fogHeightTau(q, y0, dirY, d);\n"
            << (v.secondLayer ? "    tau += fogHeightTau(uFogLayer2[slot], y0, dirY, d);\n" : "")
            << "    return exp(-tau);\n";
          break;
        }
        // q = (log a, b, h, a > 0): tau = a e^{-b(oy-h)} t g(b dirY t) in log space.
        s << "    if (q.w < 0.5 || d == 0.0) return 1.0;\n"
             "    if (q.y == 0.0) return exp(-exp(min(q.x + log(d), 80.0)));\n"
             "    float logTau = q.x - q.y * (uFogCamera.y - q.z) + log(d) + fogLogG(q.y * (ray.y / d) * d);\n"
             "    return exp(-exp(min(logTau, 80.0)));\n";
        break;
    }
    s << "  }\n";
  }
  s << "  return 1.0;\n}\n";
  if (v.engine()) {  // fog.h's order: start (fogMode), maxOpacity, cutoff (fog::engineLimits)
    const std::string start = startParam ? ", float start" : "", startArg = startParam ? ", start" : "";
    const std::string mode = "fogMode(slot, ray, d" + startArg + ")";
    s << "float fogLimited(int slot, vec3 ray, float d" << start
      << ") {\n"
         "  vec4 e = uFogEngine[slot];\n";
    if (v.cutoff) s << "  if (e.y > 0.0 && d > e.y) return 1.0;\n";
    s << (v.opacity ? "  return max(" + mode + ", e.z);\n" : "  return " + mode + ";\n") << "}\n"
      << "float fogFactor(int slot, vec3 world) {\n"
         "  vec3 ray = world - uFogCamera;\n"
      << "  return fogLimited(slot, ray, length(ray)" << (startParam ? ", uFogEngine[slot].x" : "") << ");\n}\n";
  }
  if (v.directional)  // fog::inscatterWeight * color * fog::lobe
    s << "vec3 fogSunGlow(int slot, vec3 world) {\n"
         "  vec4 sun = uFogSun[slot], sc = uFogSunColor[slot];\n"
         "  vec3 ray = world - uFogCamera;\n  float d = length(ray);\n"
         "  if (d == 0.0 || dot(sc.rgb, sc.rgb) == 0.0) return vec3(0.0);\n"
         "  float w = 1.0 - fogLimited(slot, ray, d, max(uFogEngine[slot].x, sc.w));\n"
         "  float c = clamp(dot(ray / d, sun.xyz), -1.0, 1.0);\n"
         "  float g = sun.w;\n"
         "  float den = g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c) : (1.0 + g) * (1.0 + g) - 2.0 * g * "
         "(1.0 + c);\n"
         "  float lobe = g < 1.5 ? (1.0 - g) * (1.0 + g) / (den * sqrt(den)) : (c > 0.0 ? pow(c, g - 2.0) : 0.0);\n"
         "  return w * sc.rgb * lobe;\n"
         "}\n";
  s << "int fogSlot(vec3 p) {\n";
  if (v.regions)
    s << "  for (int i = 0; i < " << v.regions << "; ++i) {\n"
      << "    vec4 lo = uRegionLo[i], hi = uRegionHi[i];\n"
      << "    bool inside = lo.w < 0.5 ? all(greaterThanEqual(p, lo.xyz)) && all(lessThanEqual(p, hi.xyz))\n"
      << "                             : dot(p - lo.xyz, p - lo.xyz) <= hi.x * hi.x;\n"
      << "    if (inside) return i + 1;\n  }\n";
  s << "  return 0;\n}\n";
  const std::string glow = v.directional ? " + fogSunGlow(slot, world)" : "";
  if (has(T::kAtmospheric)) {  // per channel: object * T + S (fog::transmittance, fog::scattered)
    s << "vec3 fogAtmospheric(int slot, vec3 world, vec3 rgb) {\n"
         "  float d = length(world - uFogCamera);\n";
    if (v.engine()) s << "  vec4 e = uFogEngine[slot];\n";
    if (v.cutoff) s << "  if (e.y > 0.0 && d > e.y) return rgb;\n";
    if (v.start) s << "  d = max(d - e.x, 0.0);\n";
    s << "  vec3 t = exp(-uFogParams[slot].xyz * d);\n"
         "  vec3 w = 1.0 - exp(-uFogInscatter[slot] * d);\n";
    if (v.opacity) s << "  t = max(t, vec3(e.z));\n  w = min(w, vec3(1.0 - e.z));\n";
    s << "  return rgb * t + w * uFogColor[slot];\n}\n";
  }
  if (v.filament || v.unreal) s << engineConventionsGlsl(v);
  s << "vec3 applyFog(vec3 rgb, vec3 world) {\n"
       "  int slot = fogSlot(world);\n";
  if (v.filament) s << "  if (uFogEngine[slot].w == 1.0) return fogFilament(slot, world, rgb);\n";
  if (v.unreal) s << "  if (uFogEngine[slot].w == 2.0) return fogUnreal(slot, world, rgb);\n";
  if (has(T::kAtmospheric))
    s << "  if (uFogType[slot] == " << int(T::kAtmospheric) << ") return fogAtmospheric(slot, world, rgb)" << glow
      << ";\n";
  s << "  return mix(uFogColor[slot], rgb, fogFactor(slot, world))" << glow << ";\n}\n";
  return s.str();
}

FogShader shader(const Fog& global, const std::vector<Region>& regions, const glm::dvec3& eye) {
  return {shaderGlsl(shaderVariant(global, regions)), shaderUniforms(global, regions, eye)};
}

}  // namespace effects::fog
