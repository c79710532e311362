// Seed 002's bolt on screen: each polyline segment drawn as an anti-aliased quad into a
// core buffer (MAX blending), an optional separable Gaussian glow at half resolution, and a
// composite that adds both over the frame. A 3-D bolt's segments are projected through the
// camera as camera-facing ribbons and depth-tested against the scene's geometry.
#include <algorithm>
#include <cmath>

#include <glm/geometric.hpp>

#include "../gpu.h"

namespace effects::render::detail {
namespace {

// Each polyline segment as a quad in pixels, widened by a one-pixel anti-aliasing margin
// and by half a width at both ends (joins overlap; the core pass blends with MAX).
std::vector<float> boltGeometry(const Lightning& l, int width, int height) {
  std::vector<float> v;
  const double sx = (l.rect.z - l.rect.x) * width / l.gridWidth, sy = (l.rect.w - l.rect.y) * height / l.gridHeight;
  auto pixel = [&](const lightning::Vertex& p) {
    return glm::dvec2(l.rect.x * width + p.x * sx, l.rect.y * height + p.y * sy);
  };
  for (const auto& line : l.polylines) {
    const double half = 0.5 * line.width * l.coreWidth, margin = half + 1.0;
    for (size_t i = 1; i < line.vertices.size(); ++i) {
      glm::dvec2 a = pixel(line.vertices[i - 1]), b = pixel(line.vertices[i]);
      glm::dvec2 d = b - a;
      double len = glm::length(d);
      d = len > 1e-9 ? d / len : glm::dvec2(1, 0);
      glm::dvec2 n(-d.y, d.x);
      a -= d * half, b += d * half;
      const float ia = line.vertices[i - 1].intensity, ib = line.vertices[i].intensity;
      auto put = [&](glm::dvec2 p, float intensity, double side) {
        glm::dvec2 q = p + n * (side * margin);
        v.insert(v.end(), {float(q.x), float(q.y), intensity, float(side * margin), float(half)});
      };
      put(a, ia, -1), put(b, ib, -1), put(b, ib, 1);
      put(a, ia, -1), put(b, ib, 1), put(a, ia, 1);
    }
  }
  return v;
}

// A 3-D bolt: each segment projected to pixels (with its NDC depth), as a screen-facing ribbon
// whose width is coreWidth pixels at the bolt's middle, scaled by perspective. Segments with an
// end behind the near plane are left out.
std::vector<float> boltGeometry3d(const Lightning& l, const View& view, int width, int height) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& line : l.polylines)
    for (const auto& v : line.vertices) lo = glm::min(lo, glm::dvec3(v.x, v.y, v.z)), hi = glm::max(hi, glm::dvec3(v.x, v.y, v.z));
  const glm::dmat4 vp(view.viewProjection);
  const double middle = std::max(1e-6, (vp * glm::dvec4(0.5 * (lo + hi), 1.0)).w);
  std::vector<float> v;
  struct Projected {
    glm::dvec2 pixel;
    double depth, w;
  };
  auto project = [&](const lightning::Vertex& p) {
    const glm::dvec4 c = vp * glm::dvec4(p.x, p.y, p.z, 1.0);
    return Projected{{(c.x / c.w * 0.5 + 0.5) * width, (0.5 - c.y / c.w * 0.5) * height}, c.z / c.w, c.w};
  };
  const double nearW = 1e-4 * middle;
  for (const auto& line : l.polylines)
    for (size_t i = 1; i < line.vertices.size(); ++i) {
      Projected a = project(line.vertices[i - 1]), b = project(line.vertices[i]);
      if (a.w < nearW || b.w < nearW) continue;
      glm::dvec2 d = b.pixel - a.pixel;
      const double len = glm::length(d);
      d = len > 1e-9 ? d / len : glm::dvec2(1, 0);
      const glm::dvec2 n(-d.y, d.x);
      const double ha = 0.5 * line.width * l.coreWidth * middle / a.w, hb = 0.5 * line.width * l.coreWidth * middle / b.w;
      a.pixel -= d * ha, b.pixel += d * hb;
      const float ia = line.vertices[i - 1].intensity, ib = line.vertices[i].intensity;
      auto put = [&](const Projected& p, double half, float intensity, double side) {
        const double margin = half + 1.0;
        const glm::dvec2 q = p.pixel + n * (side * margin);
        v.insert(v.end(), {float(q.x), float(q.y), intensity, float(side * margin), float(half), float(p.depth)});
      };
      put(a, ha, ia, -1), put(b, hb, ib, -1), put(b, hb, ib, 1);
      put(a, ha, ia, -1), put(b, hb, ib, 1), put(a, ha, ia, 1);
    }
  return v;
}

// Separable Gaussian of the core at half resolution (sigma in half-resolution pixels) into
// `glow`, through `blurred`.
std::optional<Error> glowBlur(Gpu& gpu, FrameState& f, const Lightning& l) {
  Target &core = gpu.boltCore, &blurred = gpu.blurred, &glow = gpu.glow;
  auto program = gpu.program("blur", [] { return std::pair{screenVertex(), blurFragment()}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  const double sigma = l.glowSigma / 2;
  const int radius = std::min(kMaxBlurRadius, int(std::ceil(3 * sigma)));
  std::vector<float> w(size_t(radius) + 1);
  double sum = 0;
  for (int i = 0; i <= radius; ++i) sum += (i ? 2 : 1) * (w[size_t(i)] = float(std::exp(-i * i / (2 * sigma * sigma))));
  for (float& x : w) x = float(x / sum);
  glUniform1fv(p.at("uWeights[0]"), GLsizei(w.size()), w.data());
  p.set("uRadius", radius);
  p.set("uSource", 0);
  const int hw = (f.scene.width + 1) / 2, hh = (f.scene.height + 1) / 2;
  if (!blurred.ensure(hw, hh, GL_RGBA16F, false) || !glow.ensure(hw, hh, GL_RGBA16F, false))
    return unsatisfiable("/renderer", "the glow buffers cannot be created");
  p.set("uTargetSize", glm::vec2(hw, hh));
  blurred.use();
  core.color.bind(0);
  p.set("uStep", glm::vec2(1.0f / float(hw), 0));
  glDrawArrays(GL_TRIANGLES, 0, 3);
  f.frame.passes.push_back("blurHorizontal");
  glow.use();
  blurred.color.bind(0);
  p.set("uStep", glm::vec2(0, 1.0f / float(hh)));
  glDrawArrays(GL_TRIANGLES, 0, 3);
  f.frame.passes.push_back("blurVertical");
  return std::nullopt;
}

}  // namespace

std::optional<Error> lightningPass(Gpu& gpu, FrameState& f) {
  const Scene& scene = f.scene;
  const Lightning& l = *scene.lightning;
  Target& core = gpu.boltCore;
  if (!core.ensure(scene.width, scene.height, GL_RGBA16F, false))
    return unsatisfiable("/renderer", "the lightning buffer cannot be created");
  if (l.world) {  // the scene's depth, to be tested against (not written); detached at the end
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, f.main.depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      return unsatisfiable("/renderer", "the lightning buffer cannot share the scene's depth");
  }
  core.use();
  glClear(GL_COLOR_BUFFER_BIT);
  {
    auto program = gpu.program(l.world ? "bolt:world" : "bolt", [&] { return std::pair{boltVertex(l.world), boltFragment()}; });
    if (!program.ok()) return program.error();
    Program& p = *program.value();
    glUseProgram(p.id);
    p.set("uSize", glm::vec2(scene.width, scene.height));
    const std::vector<float> data =
        l.world ? boltGeometry3d(l, f.view, scene.width, scene.height) : boltGeometry(l, scene.width, scene.height);
    const int stride = l.world ? 6 : 5;
    Vertices mesh(data, l.world ? std::vector<int>{2, 3, 1} : std::vector<int>{2, 3});
    glEnable(GL_BLEND);
    glBlendEquation(GL_MAX);
    if (l.world) glEnable(GL_DEPTH_TEST), glDepthFunc(GL_LEQUAL), glDepthMask(GL_FALSE);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(data.size() / size_t(stride)));
    if (l.world) glDisable(GL_DEPTH_TEST), glDepthMask(GL_TRUE), glDepthFunc(GL_LESS);
    glBlendEquation(GL_FUNC_ADD);
    glDisable(GL_BLEND);
    glBindVertexArray(gpu.emptyVao);
    f.frame.passes.push_back("lightning");
  }
  const bool glow = l.glowSigma > 0 && l.glowStrength > 0;
  if (glow)
    if (auto e = glowBlur(gpu, f, l)) return e;
  f.main.use();
  auto program = gpu.program(glow ? "composite:glow" : "composite",
                             [&] { return std::pair{screenVertex(), compositeFragment(glow)}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  core.color.bind(0), p.set("uCore", 0);
  if (glow) gpu.glow.color.bind(1), p.set("uGlow", 1), p.set("uGlowStrength", float(l.glowStrength));
  p.set("uColor", glm::vec3(l.color));
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  glDisable(GL_BLEND);
  if (l.world) {  // the scene's depth is not kept attached to the bolt's buffer between frames
    core.use();
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, 0);
    f.main.use();
  }
  f.frame.passes.push_back("lightningComposite");
  return std::nullopt;
}

}  // namespace effects::render::detail
