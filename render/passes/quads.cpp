// Opaque quads (walls, floors, props) with the depth test, fogged per fragment when the
// scene has fog.
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

#include "../gpu.h"

namespace effects::render {

namespace {

// A height layer as fogHeightTau reads it: (log a, b, h, a > 0).
glm::dvec4 heightLayerUniform(double a, double b, double h) {
  return {a > 0 ? std::log(a) : 0.0, b, h, a > 0 ? 1.0 : 0.0};
}

// Slot 0 = global fog; slots 1.. = regions by increasing volume (stable: ties keep their
// order), so that the shader's first containing region is regionAt()'s choice.
std::vector<FogShader::Uniform> fogUniforms(const Fog& f, const glm::dvec3& eye) {
  std::vector<size_t> order(f.regions.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return fog::volume(f.regions[a]) < fog::volume(f.regions[b]); });
  const detail::FogVariant variant = detail::fogVariant(f);
  std::vector<double> types, params, colors, lo, hi, engine, layer2, sun, sunColor, inscatter;
  auto add = [&](const fog::Fog& g) {
    types.push_back(int(g.type));
    const double cutoff = std::isfinite(g.cutoffDistance) ? g.cutoffDistance : 0.0;
    for (double x : {g.startDistance, cutoff, 1.0 - g.maxOpacity, 0.0}) engine.push_back(x);
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
  add(f.global);
  for (size_t i : order) {
    const fog::Region& r = f.regions[i];
    add(r.fog);
    glm::dvec4 a = r.shape == fog::Region::Shape::kBox ? glm::dvec4(r.min, 0) : glm::dvec4(r.center, 1);
    glm::dvec4 b = r.shape == fog::Region::Shape::kBox ? glm::dvec4(r.max, 0) : glm::dvec4(r.radius, 0, 0, 0);
    for (int k = 0; k < 4; ++k) lo.push_back(a[k]), hi.push_back(b[k]);
  }
  const std::string slots = "[" + std::to_string(types.size()) + "]", regions = "[" + std::to_string(order.size()) + "]";
  std::vector<FogShader::Uniform> out = {{"uFogCamera", "vec3", {eye.x, eye.y, eye.z}},
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
    out.push_back({"uRegionLo", "vec4" + regions, lo});
    out.push_back({"uRegionHi", "vec4" + regions, hi});
  }
  return out;
}

}  // namespace

FogShader fogShader(const Fog& f, const glm::dvec3& eye) {
  return {detail::fogGlsl(detail::fogVariant(f)), fogUniforms(f, eye)};
}

namespace detail {

void setFog(Program& p, const Fog& f, const glm::vec3& eye) {
  for (const FogShader::Uniform& u : fogUniforms(f, glm::dvec3(eye))) {
    const std::vector<float> v(u.values.begin(), u.values.end());
    const GLint at = p.at(u.name == "uFogCamera" ? u.name : u.name + "[0]");
    if (u.type.rfind("int", 0) == 0) {
      const std::vector<GLint> ints(u.values.begin(), u.values.end());
      glUniform1iv(at, GLsizei(ints.size()), ints.data());
    } else if (u.type.rfind("vec4", 0) == 0) {
      glUniform4fv(at, GLsizei(v.size() / 4), v.data());
    } else {
      glUniform3fv(at, GLsizei(v.size() / 3), v.data());
    }
  }
}

std::array<glm::dvec3, 4> quadCorners(const Quad& q) {
  glm::dvec3 n = glm::normalize(q.normal), up = q.up - n * glm::dot(q.up, n);
  if (glm::length(up) < 1e-9) up = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) - n * n.y : glm::dvec3(1, 0, 0) - n * n.x;
  up = glm::normalize(up) * (0.5 * q.size.y);
  const glm::dvec3 right = glm::normalize(glm::cross(up, n)) * (0.5 * q.size.x);
  return {q.center - right - up, q.center + right - up, q.center + right + up, q.center - right + up};
}

std::optional<Error> quadsPass(Gpu& gpu, FrameState& f) {
  const Scene& scene = f.scene;
  std::vector<float> data;
  for (const Quad& q : scene.quads) {
    const std::array<glm::dvec3, 4> c = quadCorners(q);
    for (int k : {0, 1, 2, 0, 2, 3})
      data.insert(data.end(),
                  {float(c[k].x), float(c[k].y), float(c[k].z), float(q.color.r), float(q.color.g), float(q.color.b)});
  }
  auto program = gpu.program("quad" + f.fogKey,
                             [&] { return std::pair{quadVertex(), quadFragment(f.fog ? &*f.fog : nullptr)}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  p.set("uViewProjection", f.view.viewProjection);
  if (scene.fog) setFog(p, *scene.fog, f.view.eye);
  Vertices mesh(data, {3, 3});
  glEnable(GL_DEPTH_TEST);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(data.size() / 6));
  glDisable(GL_DEPTH_TEST);
  glBindVertexArray(gpu.emptyVao);
  f.frame.passes.push_back(scene.fog ? "quads+fog" : "quads");
  return std::nullopt;
}

}  // namespace detail
}  // namespace effects::render
