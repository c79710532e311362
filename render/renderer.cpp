// A frame: the passes the scene needs, in order, then the read-back. Each pass is one
// function in passes/ (backdrop, surface wave, opaque quads, bubble with its environment cube,
// lightning with its glow, camera blend); a pass runs only when the scene has what it draws.
#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "gpu.h"

namespace effects::render {

namespace detail {

View viewOf(const Scene& s) {
  View v;
  const Camera& c = s.camera;
  v.view = glm::lookAt(glm::vec3(c.position), glm::vec3(c.target), glm::vec3(c.up));
  const double aspect = double(s.width) / s.height;
  const double fov = c.fovYDeg * kPi / 180;
  v.projection = glm::perspective(float(fov), float(aspect), float(c.nearPlane), float(c.farPlane));
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
    f.fog = fogVariant(*scene.fog);
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
