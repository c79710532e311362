// Seed 002's bolt on screen: each polyline segment drawn as an anti-aliased quad into a
// core buffer (MAX blending), an optional separable Gaussian glow at half resolution, and a
// composite that adds both over the frame. A 3-D bolt's segments are projected through the
// camera as camera-facing ribbons and depth-tested against the scene's geometry.
#include <algorithm>
#include <cmath>
#include <cstdio>

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

// The middle of a 3-D bolt's bounding box.
glm::dvec3 boltMiddle(const Lightning& l) {
  glm::dvec3 lo(INFINITY), hi(-INFINITY);
  for (const auto& line : l.polylines)
    for (const auto& v : line.vertices) lo = glm::min(lo, glm::dvec3(v.x, v.y, v.z)), hi = glm::max(hi, glm::dvec3(v.x, v.y, v.z));
  return 0.5 * (lo + hi);
}

// A 3-D bolt: each segment projected to pixels (with its NDC depth), as a screen-facing ribbon
// whose width is coreWidth pixels at the bolt's middle, scaled by perspective. Segments with an
// end behind the near plane are left out. Each vertex carries the fog's transmittance from the
// eye (the channels' mean; 1 without fog): the core buffer holds the light as emitted (red,
// what the glow spreads) and as it reaches the eye (green, what the composite draws sharp).
std::vector<float> boltGeometry3d(const Lightning& l, const View& view, int width, int height, const Fog* fog) {
  const glm::dmat4 vp(view.viewProjection);
  const glm::dvec3 eye(view.eye);
  const double middle = std::max(1e-6, (vp * glm::dvec4(boltMiddle(l), 1.0)).w);
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
      auto through = [&](const lightning::Vertex& v) {  // the fog's transmittance from the eye
        if (!fog) return 1.0f;
        const glm::dvec3 t = fog::sampleAt(fog->global, fog->regions, eye, {v.x, v.y, v.z}).transmittance;
        return float((t.r + t.g + t.b) / 3);
      };
      const float ia = line.vertices[i - 1].intensity, ib = line.vertices[i].intensity;
      const float ta = through(line.vertices[i - 1]), tb = through(line.vertices[i]);
      auto put = [&](const Projected& p, double half, float intensity, float t, double side) {
        const double margin = half + 1.0;
        const glm::dvec2 q = p.pixel + n * (side * margin);
        v.insert(v.end(), {float(q.x), float(q.y), intensity, float(side * margin), float(half), float(p.depth), t});
      };
      put(a, ha, ia, ta, -1), put(b, hb, ib, tb, -1), put(b, hb, ib, tb, 1);
      put(a, ha, ia, ta, -1), put(b, hb, ib, tb, 1), put(a, ha, ia, ta, 1);
    }
  return v;
}

// The normalised taps of a Gaussian of `sigma` texels, centre first (radius <= kMaxBlurRadius).
std::vector<float> gaussianTaps(double sigma) {
  const int radius = std::min(kMaxBlurRadius, std::max(1, int(std::ceil(3 * sigma))));
  std::vector<float> w(size_t(radius) + 1);
  double sum = 0;
  for (int i = 0; i <= radius; ++i) sum += (i ? 2 : 1) * (w[size_t(i)] = float(std::exp(-i * i / (2 * sigma * sigma))));
  for (float& x : w) x = float(x / sum);
  return w;
}

// Separable Gaussian of the core at half resolution (sigma in half-resolution pixels) into
// `glow`, through `blurred`.
std::optional<Error> glowBlur(Gpu& gpu, FrameState& f, const Lightning& l) {
  Target &core = gpu.boltCore, &blurred = gpu.blurred, &glow = gpu.glow;
  auto program = gpu.program("blur", [] { return std::pair{screenVertex(), blurFragment()}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  const std::vector<float> w = gaussianTaps(l.glowSigma / 2);  // glowSigma > 0: a radius of at least 1
  const int radius = int(w.size()) - 1;
  glUniform1fv(p.at("uWeights[0]"), GLsizei(w.size()), w.data());
  p.set("uRadius", radius);
  p.set("uSource", 0);
  f.frame.glow = "gaussian sigma " + std::to_string(l.glowSigma) + " px";
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

// The fitted APSF kernel for this medium (kept per render thread: an animation's frames share it).
Result<const glow::Kernel*> apsfKernel(Gpu& gpu, const glow::Medium& m, glow::Method method) {
  const auto key = std::make_tuple(m.thickness, m.forwardScattering, int(method));
  if (auto it = gpu.apsfKernels.find(key); it != gpu.apsfKernels.end()) return &it->second;
  glow::KernelOptions o;
  o.method = method;
  auto k = glow::kernel(m, o);
  if (!k.ok()) return k.error();
  if (gpu.apsfKernels.size() >= 16) gpu.apsfKernels.erase(gpu.apsfKernels.begin());
  return &gpu.apsfKernels.emplace(key, std::move(k.value())).first->second;
}

// The APSF glow of a 3-D bolt in fog: each fitted Gaussian (sigma in radians -> pixels through
// the camera's focal length, small-angle) as a separable blur of the core's mip level at which it
// is 8 to 16 texels wide, into apsfGlow[k]. Returns the composite's weight of each.
Result<std::vector<float>> apsfBlur(Gpu& gpu, FrameState& f, const Lightning& l) {
  const Scene& scene = f.scene;
  const glm::dvec3 eye(f.view.eye);
  glow::Medium m;
  m.thickness = glow::thicknessAlong(scene.fog->global, scene.fog->regions, eye, boltMiddle(l));
  const int region = fog::regionAt(scene.fog->regions, boltMiddle(l));
  m.forwardScattering = l.forwardScattering.value_or(
      glow::forwardScatteringOf(region < 0 ? scene.fog->global : scene.fog->regions[size_t(region)].fog));
  auto kernel = apsfKernel(gpu, m, l.apsfMethod);
  if (!kernel.ok()) return kernel.error();
  const glow::Kernel& k = *kernel.value();
  char text[160];
  std::snprintf(text, sizeof text, "apsf T %.4g q %.3g %s (misplaced %.2g, halo radius %.3g deg)", m.thickness,
                m.forwardScattering, glow::toString(k.method), k.misplaced.value_or(0), k.haloRadius * 180 / kPi);
  f.frame.glow = text;
  auto program = gpu.program("blur:lod", [] { return std::pair{screenVertex(), blurFragment(true)}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  p.set("uSource", 0);
  Target& core = gpu.boltCore;
  core.color.bind(0);
  glGenerateMipmap(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR_MIPMAP_NEAREST);
  const double focal = 0.5 * scene.height / std::tan(0.5 * scene.camera.fovYDeg * kPi / 180);
  const int maxLevel = int(std::floor(std::log2(std::max(scene.width, scene.height))));
  std::vector<float> weights;
  for (size_t i = 0; i < k.gaussians.size() && i < 3; ++i) {
    const double sigma = std::max(0.5, k.gaussians[i].sigma * focal);
    const int level = std::clamp(int(std::floor(std::log2(sigma / 8))), 0, maxLevel);
    const int w = std::max(1, (scene.width + (1 << level) - 1) >> level), h = std::max(1, (scene.height + (1 << level) - 1) >> level);
    Target &temp = gpu.apsfBlurred[i], &out = gpu.apsfGlow[i];
    if (!temp.ensure(w, h, GL_RGBA16F, false) || !out.ensure(w, h, GL_RGBA16F, false))
      return unsatisfiable("/renderer", "the glow buffers cannot be created");
    const std::vector<float> taps = gaussianTaps(sigma / (1 << level));
    glUniform1fv(p.at("uWeights[0]"), GLsizei(taps.size()), taps.data());
    p.set("uRadius", int(taps.size()) - 1);
    p.set("uTargetSize", glm::vec2(w, h));
    temp.use();
    core.color.bind(0);
    p.set("uLod", float(level));
    p.set("uStep", glm::vec2(1.0f / float(w), 0));
    glDrawArrays(GL_TRIANGLES, 0, 3);
    out.use();
    temp.color.bind(0);
    p.set("uLod", 0.0f);
    p.set("uStep", glm::vec2(0, 1.0f / float(h)));
    glDrawArrays(GL_TRIANGLES, 0, 3);
    // The Gaussian's share of the light (its weight: the integral over solid angle), scattered.
    weights.push_back(float(l.glowStrength * l.radiance * k.scattered * k.gaussians[i].weight));
  }
  core.color.bind(0);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
  f.frame.passes.push_back("glowApsf");
  return weights;
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
        l.world ? boltGeometry3d(l, f.view, scene.width, scene.height, scene.fog ? &*scene.fog : nullptr)
                : boltGeometry(l, scene.width, scene.height);
    const int stride = l.world ? 7 : 5;
    Vertices mesh(data, l.world ? std::vector<int>{2, 3, 2} : std::vector<int>{2, 3});
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
  // A 3-D bolt seen through fog glows by the fog's APSF; otherwise today's Gaussian.
  const bool apsf = l.world && scene.fog && l.glowStrength > 0;
  const bool glow = !apsf && l.glowSigma > 0 && l.glowStrength > 0;
  std::vector<float> apsfWeights;
  if (glow)
    if (auto e = glowBlur(gpu, f, l)) return e;
  if (apsf) {
    auto w = apsfBlur(gpu, f, l);
    if (!w.ok()) return w.error();
    apsfWeights = std::move(w.value());
  }
  if (!glow && !apsf) f.frame.glow = "none";
  const int components = int(apsfWeights.size());
  f.main.use();
  auto program = gpu.program(glow ? "composite:glow" : "composite:apsf" + std::to_string(components),
                             [&] { return std::pair{screenVertex(), compositeFragment(glow, components)}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  core.color.bind(0), p.set("uCore", 0);
  if (glow) gpu.glow.color.bind(1), p.set("uGlow", 1), p.set("uGlowStrength", float(l.glowStrength));
  for (int k = 0; k < components; ++k) {
    gpu.apsfGlow[k].color.bind(1 + k);
    p.set("uApsf" + std::to_string(k), 1 + k);
  }
  if (components > 0) glUniform1fv(p.at("uApsfWeight[0]"), components, apsfWeights.data());
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
