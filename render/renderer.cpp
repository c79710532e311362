// A frame: the passes the scene needs, in order, then the read-back. Each pass is one
// function in passes/ (backdrop, surface wave, opaque quads, bubble with its environment cube,
// lightning with its glow, camera blend); a pass runs only when the scene has what it draws.
#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "gpu.h"

namespace effects::render {

namespace detail {

namespace {

// The depth range the frame needs: the camera's near and far planes, narrowed to what the scene
// holds in the world (bubbles, the part of each quad in view, a world bolt) with room to spare.
// Near the far plane a depth buffer resolves about far/near / 2^24 of the range: near 1e-7 and
// far 1e7 put everything at depth 1, and the depth test dropped a bubble at 4. Narrowing never
// clips what the camera's planes would not: near only rises to half the nearest content's
// depth, far only falls to twice the farthest's.
glm::dvec2 depthRange(const Scene& s) {
  const Camera& c = s.camera;
  const glm::dvec3 forward = glm::normalize(c.target - c.position);
  const glm::dvec3 right = glm::normalize(glm::cross(forward, c.up)), up = glm::cross(right, forward);
  const double ty = std::tan(c.fovYDeg * kPi / 360), tx = ty * s.width / s.height;
  double lo = INFINITY, hi = -INFINITY;
  auto add = [&](const glm::dvec3& p, double radius) {
    const double z = glm::dot(p - c.position, forward);
    lo = std::min(lo, z - radius), hi = std::max(hi, z + radius);
  };
  for (const Bubble& b : s.bubbles) add(b.center, 2 * b.radius);  // the wobble stays within the radius
  // A quad (a floor may pass under the camera): its part inside the frustum's four sides, in
  // camera space (x right, y up, z ahead), clipped plane by plane.
  for (const Quad& q : s.quads) {
    std::vector<glm::dvec3> poly;
    for (const glm::dvec3& p : quadCorners(q))  // as the quads pass draws it
      poly.push_back({glm::dot(p - c.position, right), glm::dot(p - c.position, up), glm::dot(p - c.position, forward)});
    for (const glm::dvec3 plane : {glm::dvec3(-1, 0, tx), glm::dvec3(1, 0, tx), glm::dvec3(0, -1, ty),
                                   glm::dvec3(0, 1, ty)}) {  // inside: dot(plane, p) >= 0
      std::vector<glm::dvec3> kept;
      for (size_t i = 0; i < poly.size(); ++i) {
        const glm::dvec3 &a = poly[i], &b = poly[(i + 1) % poly.size()];
        const double da = glm::dot(plane, a), db = glm::dot(plane, b);
        if (da >= 0) kept.push_back(a);
        if ((da >= 0) != (db >= 0)) kept.push_back(a + (b - a) * (da / (da - db)));
      }
      poly = std::move(kept);
    }
    for (const glm::dvec3& p : poly) lo = std::min(lo, p.z), hi = std::max(hi, p.z);
  }
  if (s.lightning && s.lightning->world)
    for (const auto& line : s.lightning->polylines)
      for (const auto& v : line.vertices) add(glm::dvec3(v.x, v.y, v.z), 0);
  if (!(hi > lo) || !std::isfinite(lo) || !std::isfinite(hi)) return {c.nearPlane, c.farPlane};
  const double nearPlane = lo > 2 * c.nearPlane ? 0.5 * lo : c.nearPlane;
  const double farPlane = std::max(nearPlane * 2, std::min(c.farPlane, 2 * hi));
  return {nearPlane, farPlane};
}

}  // namespace

View viewOf(const Scene& s) {
  View v;
  const Camera& c = s.camera;
  v.view = glm::lookAt(glm::vec3(c.position), glm::vec3(c.target), glm::vec3(c.up));
  const double aspect = double(s.width) / s.height;
  const double fov = c.fovYDeg * kPi / 180;
  const glm::dvec2 range = depthRange(s);
  v.projection = glm::perspective(float(fov), float(aspect), float(range.x), float(range.y));
  v.viewProjection = v.projection * v.view;
  v.tanHalfFov = glm::vec2(std::tan(fov / 2) * aspect, std::tan(fov / 2));
  v.eye = glm::vec3(c.position);
  return v;
}

}  // namespace detail

struct Renderer::Impl {
  detail::Gpu gpu;
  Result<Frame> render(const Scene& scene);
};

namespace {

using namespace detail;

// Reads the main target back (rows bottom-up in GL) as floats, flipped and un-premultiplied.
Result<Image> readBackFloat(const Scene& scene) {
  const size_t w = size_t(scene.width), h = size_t(scene.height);
  std::vector<float> pixels(w * h * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, scene.width, scene.height, GL_RGBA, GL_FLOAT, pixels.data());
  if (GLenum e = glGetError(); e != GL_NO_ERROR) return unsatisfiable("/renderer", "OpenGL error " + std::to_string(e));
  Image image{scene.width, scene.height, std::vector<float>(w * h * 4), {}};
  for (size_t y = 0; y < h; ++y) {
    const float* src = &pixels[(h - 1 - y) * w * 4];
    float* dst = &image.rgba[y * w * 4];
    for (size_t x = 0; x < w; ++x, src += 4, dst += 4) {
      float a = std::clamp(src[3], 0.0f, 1.0f);
      for (int c = 0; c < 3; ++c) dst[c] = a > 0 ? std::clamp(src[c] / a, 0.0f, 1.0f) : 0.0f;
      dst[3] = a;
    }
  }
  return image;
}

// For an 8-bit PNG: the GPU un-premultiplies, flips and rounds the frame into an RGBA8 target
// (resolveFragment), and the read-back is the PNG's bytes, a quarter of the floats' size.
Result<Image> readBack8(Gpu& gpu, const Scene& scene) {
  auto program = gpu.program("resolve8", [] { return std::pair{screenVertex(), resolveFragment()}; });
  if (!program.ok()) return program.error();
  if (!gpu.resolved.ensure(scene.width, scene.height, GL_RGBA8, false))
    return unsatisfiable("/renderer", "the 8-bit frame buffer cannot be created");
  gpu.resolved.use();
  Program& p = *program.value();
  glUseProgram(p.id);
  gpu.main.color.bind(0), p.set("uFrame", 0);
  glDrawArrays(GL_TRIANGLES, 0, 3);
  Image image{scene.width, scene.height, {}, std::vector<uint8_t>(size_t(scene.width) * size_t(scene.height) * 4)};
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, scene.width, scene.height, GL_RGBA, GL_UNSIGNED_BYTE, image.rgba8.data());
  if (GLenum e = glGetError(); e != GL_NO_ERROR) return unsatisfiable("/renderer", "OpenGL error " + std::to_string(e));
  return image;
}

}  // namespace

Result<Frame> Renderer::Impl::render(const Scene& scene) {
  Stopwatch watch;
  gpu.compiled = 0;
  if (scene.width < 1 || scene.height < 1 || scene.width > gpu.maxTextureSize || scene.height > gpu.maxTextureSize)
    return overLimit("/width", "the renderer's largest image side is " + std::to_string(gpu.maxTextureSize));
  if (scene.lightning && (scene.lightning->gridWidth < 1 || scene.lightning->gridHeight < 1))
    return invalid("/lightning/grid", "must have at least one cell");

  // The frame: its main target cleared, the fog variant, the backdrop image uploaded.
  FrameState f{scene, viewOf(scene), gpu.main, {}, {}, {}, {}};
  const GLenum mainFormat = scene.bitDepth == 16 && gpu.floatBlend ? GL_RGBA32F : GL_RGBA16F;
  if (!f.main.ensure(scene.width, scene.height, mainFormat, true))
    return unsatisfiable("/renderer", "the frame buffer cannot be created");
  f.main.use();
  glClearColor(0, 0, 0, 0);
  glClearDepthf(1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBindVertexArray(gpu.emptyVao);
  if (scene.fog) {
    f.fog = fog::shaderVariant(scene.fog->global, scene.fog->regions);
    f.fogKey = ":" + f.fog->key();
  }
  const Background& bg = scene.background;
  if (bg.kind == Background::Kind::kImage) {
    auto data = premultiplied(bg.image);
    f.backgroundImage =
        texture2D(bg.image.width, bg.image.height, GL_RGBA32F, GL_RGBA, GL_FLOAT, data.data(), GL_CLAMP_TO_EDGE);
  }

  // The passes this scene needs, back to front.
  using Pass = std::optional<Error> (*)(Gpu&, FrameState&);
  std::vector<Pass> passes = {backgroundPass};
  if (scene.wave && !scene.wave->onQuad) passes.push_back(surfaceWavePass);  // over the backdrop
  if (!scene.quads.empty()) passes.push_back(quadsPass);
  if (scene.wave && scene.wave->onQuad) passes.push_back(surfaceWavePass);  // on its quad
  if (!scene.bubbles.empty()) passes.push_back(bubblePass);
  if (scene.lightning && !scene.lightning->polylines.empty()) passes.push_back(lightningPass);
  if (scene.blend && scene.blend->amount > 0) passes.push_back(cameraBlendPass);
  for (Pass pass : passes)
    if (auto e = pass(gpu, f)) return *e;
  glFinish();
  f.frame.drawMs = watch.ms();

  Stopwatch read;
  auto image = scene.bitDepth == 8 ? readBack8(gpu, scene) : readBackFloat(scene);
  if (!image.ok()) return image.error();
  f.frame.image = std::move(image.value());
  f.frame.readMs = read.ms();
  f.frame.variantsCompiled = gpu.compiled;
  f.frame.variantsCached = int(gpu.programs.size());
  f.frame.ms = watch.ms();
  return std::move(f.frame);
}

std::string Frame::passList() const {
  std::string out;
  for (const auto& p : passes) out += (out.empty() ? "" : ",") + p;
  return out;
}

Renderer::Renderer() : impl_(std::make_unique<Impl>()) {}
Renderer::~Renderer() = default;

Result<std::unique_ptr<Renderer>> Renderer::create(const std::string& platform) {
  auto egl = createContext(platform);
  if (!egl.ok()) return egl.error();
  std::unique_ptr<Renderer> r(new Renderer());
  detail::Gpu& m = r->impl_->gpu;
  m.egl = egl.value();
  const char* name = reinterpret_cast<const char*>(glGetString(GL_RENDERER));
  m.description = std::string(name ? name : "unknown") + " via " + m.egl.platform;
  glGetIntegerv(GL_MAX_TEXTURE_SIZE, &m.maxTextureSize);
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  bool colorFloat = false;
  for (GLint i = 0; i < n; ++i) {
    std::string e = reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)));
    colorFloat |= e == "GL_EXT_color_buffer_float";
    m.floatBlend |= e == "GL_EXT_float_blend";
  }
  if (!colorFloat)
    return unsatisfiable("/renderer", m.description + " cannot render to float buffers (GL_EXT_color_buffer_float)");
  glGenVertexArrays(1, &m.emptyVao);
  return r;
}

Result<Frame> Renderer::render(const Scene& scene) { return impl_->render(scene); }

Result<Frame> Renderer::render(Scene& scene, const Sequence& sequence) {
  Frame total;
  for (int i = 0; i < sequence.count; ++i) {
    Stopwatch prepare;  // moving the scene on is part of drawing its frame
    if (sequence.prepare) sequence.prepare(scene, i);
    const double prepareMs = prepare.ms();
    auto frame = impl_->render(scene);
    if (!frame.ok()) return frame.error();
    total.ms += prepareMs + frame.value().ms;
    total.drawMs += prepareMs + frame.value().drawMs;
    total.readMs += frame.value().readMs;
    total.variantsCompiled += frame.value().variantsCompiled;
    total.variantsCached = frame.value().variantsCached;
    total.passes = frame.value().passes;
    if (sequence.consume)
      if (auto e = sequence.consume(frame.value(), i)) return *e;
  }
  return total;
}
const std::string& Renderer::description() const { return impl_->gpu.description; }

}  // namespace effects::render
