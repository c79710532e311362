// The passes: backdrop, surface wave, opaque quads, bubble (with its environment cube),
// lightning (core, blur H, blur V, composite), camera blend; read-back. Each runs only when
// the scene has what it draws.
#include <GLES3/gl3.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glm/mat3x3.hpp>
#include <glm/mat4x4.hpp>

#include <effects/tangents.h>

#include "internal.h"

namespace effects::render {
namespace {

using namespace detail;

constexpr double kPi = 3.14159265358979323846;
constexpr int kEnvironmentSize = 256;
constexpr int kMaxBlurRadius = 64;

// ---- GL objects ------------------------------------------------------------------------
struct Program {
  GLuint id = 0;
  std::map<std::string, GLint> locations;
  GLint at(const std::string& name) {
    auto it = locations.find(name);
    if (it == locations.end()) it = locations.emplace(name, glGetUniformLocation(id, name.c_str())).first;
    return it->second;
  }
  void set(const std::string& n, float v) { glUniform1f(at(n), v); }
  void set(const std::string& n, int v) { glUniform1i(at(n), v); }
  void set(const std::string& n, glm::vec2 v) { glUniform2f(at(n), v.x, v.y); }
  void set(const std::string& n, glm::vec3 v) { glUniform3f(at(n), v.x, v.y, v.z); }
  void set(const std::string& n, glm::vec4 v) { glUniform4f(at(n), v.x, v.y, v.z, v.w); }
  void set(const std::string& n, const glm::mat3& m) { glUniformMatrix3fv(at(n), 1, GL_FALSE, glm::value_ptr(m)); }
  void set(const std::string& n, const glm::mat4& m) { glUniformMatrix4fv(at(n), 1, GL_FALSE, glm::value_ptr(m)); }
};

Result<GLuint> compile(GLenum stage, const std::string& source) {
  GLuint s = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(s, 1, &text, nullptr);
  glCompileShader(s);
  GLint ok = 0;
  glGetShaderiv(s, GL_COMPILE_STATUS, &ok);
  if (ok) return s;
  char log[2048] = {};
  glGetShaderInfoLog(s, sizeof log, nullptr, log);
  glDeleteShader(s);
  return unsatisfiable("/renderer", std::string("shader does not compile: ") + log);
}

struct Texture {
  GLuint id = 0;
  GLenum target = GL_TEXTURE_2D;
  Texture() = default;
  Texture(const Texture&) = delete;
  Texture& operator=(const Texture&) = delete;
  Texture(Texture&& o) noexcept : id(std::exchange(o.id, 0)), target(o.target) {}
  Texture& operator=(Texture&& o) noexcept {
    if (this != &o) {
      if (id) glDeleteTextures(1, &id);
      id = std::exchange(o.id, 0), target = o.target;
    }
    return *this;
  }
  ~Texture() {
    if (id) glDeleteTextures(1, &id);
  }
  void make(GLenum t) {
    target = t;
    glGenTextures(1, &id);
    glBindTexture(t, id);
    glTexParameteri(t, GL_TEXTURE_MIN_FILTER, GL_LINEAR);
    glTexParameteri(t, GL_TEXTURE_MAG_FILTER, GL_LINEAR);
    GLenum wrap = t == GL_TEXTURE_CUBE_MAP ? GL_CLAMP_TO_EDGE : GL_REPEAT;
    glTexParameteri(t, GL_TEXTURE_WRAP_S, wrap);
    glTexParameteri(t, GL_TEXTURE_WRAP_T, wrap);
  }
  void bind(int unit) const {
    glActiveTexture(GL_TEXTURE0 + unit);
    glBindTexture(target, id);
  }
};

Texture texture2D(int w, int h, GLenum internal, GLenum format, GLenum type, const void* data, GLenum wrap = GL_REPEAT) {
  Texture t;
  t.make(GL_TEXTURE_2D);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_S, wrap);
  glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, wrap);
  glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
  glTexImage2D(GL_TEXTURE_2D, 0, internal, w, h, 0, format, type, data);
  return t;
}

// A colour texture (and optionally depth) to draw into.
struct Target {
  GLuint fbo = 0, depth = 0;
  Texture color;
  int width = 0, height = 0;
  Target() = default;
  Target(const Target&) = delete;
  Target& operator=(const Target&) = delete;
  ~Target() {
    if (fbo) glDeleteFramebuffers(1, &fbo);
    if (depth) glDeleteRenderbuffers(1, &depth);
  }
  bool create(int w, int h, GLenum internal, bool withDepth) {
    width = w, height = h;
    color = texture2D(w, h, internal, GL_RGBA, internal == GL_RGBA32F ? GL_FLOAT : GL_HALF_FLOAT, nullptr, GL_CLAMP_TO_EDGE);
    glGenFramebuffers(1, &fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, color.id, 0);
    if (withDepth) {
      glGenRenderbuffers(1, &depth);
      glBindRenderbuffer(GL_RENDERBUFFER, depth);
      glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, w, h);
      glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    }
    return glCheckFramebufferStatus(GL_FRAMEBUFFER) == GL_FRAMEBUFFER_COMPLETE;
  }
  void use() const {
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glViewport(0, 0, width, height);
  }
};

// Interleaved float vertices with the given attribute sizes at locations 0, 1, ...
struct Vertices {
  GLuint vao = 0, vbo = 0, ibo = 0;
  Vertices(const std::vector<float>& data, std::vector<int> sizes, const std::vector<uint32_t>* indices = nullptr) {
    glGenVertexArrays(1, &vao);
    glBindVertexArray(vao);
    glGenBuffers(1, &vbo);
    glBindBuffer(GL_ARRAY_BUFFER, vbo);
    glBufferData(GL_ARRAY_BUFFER, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STREAM_DRAW);
    const int stride = std::accumulate(sizes.begin(), sizes.end(), 0);
    for (size_t i = 0, offset = 0; i < sizes.size(); offset += size_t(sizes[i]), ++i) {
      glEnableVertexAttribArray(GLuint(i));
      glVertexAttribPointer(GLuint(i), sizes[i], GL_FLOAT, GL_FALSE, stride * 4, reinterpret_cast<void*>(offset * 4));
    }
    if (indices) {
      glGenBuffers(1, &ibo);
      glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, ibo);
      glBufferData(GL_ELEMENT_ARRAY_BUFFER, GLsizeiptr(indices->size() * 4), indices->data(), GL_STREAM_DRAW);
    }
  }
  ~Vertices() {
    glBindVertexArray(0);
    glDeleteBuffers(1, &vbo);
    if (ibo) glDeleteBuffers(1, &ibo);
    glDeleteVertexArrays(1, &vao);
  }
};

// ---- generated textures ----------------------------------------------------------------
// A tileable height field of integer-frequency waves -> tangent-space normal map (RGBA8).
std::vector<uint8_t> normalMap(int size, uint64_t seed) {
  Rng rng(seed);
  struct Wave {
    double fx, fy, amp, phase;
  };
  std::vector<Wave> waves;
  for (int i = 0; i < 7; ++i) {
    double fx = std::floor(rng.uniform() * 7) - 3, fy = 1 + std::floor(rng.uniform() * 5);
    waves.push_back({fx, fy, 0.05 / std::sqrt(fx * fx + fy * fy), 2 * kPi * rng.uniform()});
  }
  std::vector<uint8_t> out(size_t(size) * size * 4);
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double u = (x + 0.5) / size, v = (y + 0.5) / size, dx = 0, dy = 0;
      for (const Wave& w : waves) {
        double c = std::cos(2 * kPi * (w.fx * u + w.fy * v) + w.phase) * w.amp * 2 * kPi;
        dx += c * w.fx, dy += c * w.fy;
      }
      glm::dvec3 n = glm::normalize(glm::dvec3(-dx, -dy, 1.0));
      uint8_t* p = &out[(size_t(y) * size + x) * 4];
      for (int c = 0; c < 3; ++c) p[c] = uint8_t(std::lround((n[c] * 0.5 + 0.5) * 255));
      p[3] = 255;
    }
  return out;
}

// Smooth tileable single-channel pattern in [0, 1] (the wave's alpha, the flow texture).
std::vector<uint8_t> softPattern(int size, int channels, uint64_t seed, double lo, double hi) {
  Rng rng(seed);
  double f[4][3];
  for (auto& w : f) w[0] = 1 + std::floor(rng.uniform() * 4), w[1] = 1 + std::floor(rng.uniform() * 4), w[2] = 2 * kPi * rng.uniform();
  std::vector<uint8_t> out(size_t(size) * size * size_t(channels));
  for (int y = 0; y < size; ++y)
    for (int x = 0; x < size; ++x) {
      double u = double(x) / size, v = double(y) / size;
      for (int c = 0; c < channels; ++c) {
        double s = 0;
        for (int k = 0; k < 4; ++k) s += std::sin(2 * kPi * (f[k][0] * u + f[k][1] * v) + f[k][2] + c * 0.7);
        double t = 0.5 + s / 8.0;  // in [0, 1]
        out[(size_t(y) * size + x) * size_t(channels) + size_t(c)] = uint8_t(std::lround((lo + (hi - lo) * t) * 255));
      }
    }
  return out;
}

std::vector<float> premultiplied(const Image& image) {
  std::vector<float> p = image.rgba;
  for (size_t i = 0; i < p.size(); i += 4)
    for (int c = 0; c < 3; ++c) p[i + size_t(c)] *= p[i + 3];
  return p;
}

glm::vec4 premultiplied(const glm::dvec4& c) { return glm::vec4(glm::dvec3(c) * c.a, c.a); }

}  // namespace

// ---- Renderer ------------------------------------------------------------------------------
struct Renderer::Impl {
  EglContext egl;
  std::string description;
  int maxTextureSize = 0;
  bool floatBlend = false;
  GLuint emptyVao = 0;
  std::map<std::string, Program> programs;
  int compiled = 0;
  Texture normalA, normalB, waveAlpha, defaultFlow;
  std::vector<float> waveVertices;  // the surface-wave quad with its MikkTSpace frames
  std::vector<uint32_t> waveIndices;

  ~Impl() {
    if (egl.context) {
      for (auto& p : programs) glDeleteProgram(p.second.id);
      if (emptyVao) glDeleteVertexArrays(1, &emptyVao);
      normalA = Texture(), normalB = Texture(), waveAlpha = Texture(), defaultFlow = Texture();
      destroyContext(egl);
    }
  }

  Result<Program*> program(const std::string& key, const std::string& vs, const std::string& fs) {
    if (auto it = programs.find(key); it != programs.end()) return &it->second;
    auto v = compile(GL_VERTEX_SHADER, vs);
    if (!v.ok()) return v.error();
    auto f = compile(GL_FRAGMENT_SHADER, fs);
    if (!f.ok()) {
      glDeleteShader(v.value());
      return f.error();
    }
    GLuint id = glCreateProgram();
    glAttachShader(id, v.value());
    glAttachShader(id, f.value());
    glLinkProgram(id);
    glDeleteShader(v.value());
    glDeleteShader(f.value());
    GLint ok = 0;
    glGetProgramiv(id, GL_LINK_STATUS, &ok);
    if (!ok) {
      char log[2048] = {};
      glGetProgramInfoLog(id, sizeof log, nullptr, log);
      glDeleteProgram(id);
      return unsatisfiable("/renderer", "program " + key + " does not link: " + log);
    }
    ++compiled;
    Program& p = programs[key];
    p.id = id;
    return &p;
  }

  const Texture& flowTexture(const Bubble& b, Texture& owned) {
    if (!b.flowTexture.rgba.empty()) {
      auto data = premultiplied(b.flowTexture);
      owned = texture2D(b.flowTexture.width, b.flowTexture.height, GL_RGBA32F, GL_RGBA, GL_FLOAT, data.data());
      return owned;
    }
    if (!defaultFlow.id) {
      auto data = softPattern(128, 3, 11, 0.8, 1.0);
      defaultFlow = texture2D(128, 128, GL_RGB8, GL_RGB, GL_UNSIGNED_BYTE, data.data());
    }
    return defaultFlow;
  }

  // Generated once per context: the two normal maps, the alpha texture, and the quad with
  // its MikkTSpace frames (seed 004's TBN for the ripple lighting).
  std::optional<Error> ensureWave() {
    if (normalA.id) return std::nullopt;
    tangents::Mesh quad{{{-1, -1, 0}, {1, -1, 0}, {1, 1, 0}, {-1, 1, 0}},
                        {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}, {0, 0, 1}},
                        {{0, 0}, {1, 0}, {1, 1}, {0, 1}},
                        {0, 1, 2, 0, 2, 3}};
    auto frames = tangents::generate(quad, tangents::Options{});
    if (!frames.ok()) return frames.error();
    const auto& out = frames.value();
    for (size_t i = 0; i < out.remap.size(); ++i) {
      uint32_t src = out.remap[i];
      const glm::vec3& p = quad.positions[src];
      const glm::vec2& uv = quad.uvs[src];
      const glm::vec3& n = out.normals[i];
      const glm::vec4& t = out.tangents[i];
      waveVertices.insert(waveVertices.end(), {p.x, p.y, uv.x, uv.y, n.x, n.y, n.z, t.x, t.y, t.z, t.w});
    }
    waveIndices = out.indices;
    auto a = normalMap(256, 3), b = normalMap(256, 7);
    normalA = texture2D(256, 256, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, a.data());
    normalB = texture2D(256, 256, GL_RGBA8, GL_RGBA, GL_UNSIGNED_BYTE, b.data());
    auto alpha = softPattern(128, 1, 5, 0.2, 1.0);
    waveAlpha = texture2D(128, 128, GL_R8, GL_RED, GL_UNSIGNED_BYTE, alpha.data());
    return std::nullopt;
  }

  Result<Frame> render(const Scene& scene);
};

namespace {

struct View {
  glm::mat4 view, projection, viewProjection;
  glm::vec2 tanHalfFov;
  glm::vec3 eye;
};

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

void setBackground(Program& p, const Background& b, const Texture* image) {
  switch (b.kind) {
    case Background::Kind::kColor: p.set("uColor", premultiplied(b.color)); break;
    case Background::Kind::kGradient:
      p.set("uTop", premultiplied(b.top));
      p.set("uBottom", premultiplied(b.bottom));
      break;
    case Background::Kind::kImage:
      image->bind(3);
      p.set("uImage", 3);
      break;
  }
}

// Slot 0 = global fog; slots 1.. = regions by increasing volume (stable: ties keep their
// order), so that the shader's first containing region is regionAt()'s choice.
void setFog(Program& p, const Fog& f, const glm::vec3& eye) {
  std::vector<size_t> order(f.regions.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](size_t a, size_t b) { return fog::volume(f.regions[a]) < fog::volume(f.regions[b]); });
  std::vector<int> types;
  std::vector<float> params, colors, lo, hi;
  auto add = [&](const fog::Fog& g) {
    types.push_back(int(g.type));
    glm::dvec4 q(0);
    switch (g.type) {
      case fog::FogType::kX3dLinear:
      case fog::FogType::kX3dExponential: q.x = g.visibilityRange; break;
      case fog::FogType::kGlLinear: q = {g.start, g.end, 0, 0}; break;
      case fog::FogType::kGlExp:
      case fog::FogType::kGlExp2: q.x = g.density; break;
      case fog::FogType::kDistanceExp2: q.x = g.distanceCoefficient; break;
      case fog::FogType::kDistanceGaussian: q = {g.distanceCoefficient, g.peak, 0, 0}; break;
      case fog::FogType::kHeight:
        q = {g.density > 0 ? std::log(g.density) : 0.0, g.heightFalloff, g.baseHeight, g.density > 0 ? 1.0 : 0.0};
        break;
    }
    for (int i = 0; i < 4; ++i) params.push_back(float(q[i]));
    for (int i = 0; i < 3; ++i) colors.push_back(float(g.color[i]));
  };
  add(f.global);
  for (size_t i : order) {
    const fog::Region& r = f.regions[i];
    add(r.fog);
    glm::dvec4 a = r.shape == fog::Region::Shape::kBox ? glm::dvec4(r.min, 0) : glm::dvec4(r.center, 1);
    glm::dvec4 b = r.shape == fog::Region::Shape::kBox ? glm::dvec4(r.max, 0) : glm::dvec4(r.radius, 0, 0, 0);
    for (int k = 0; k < 4; ++k) lo.push_back(float(a[k])), hi.push_back(float(b[k]));
  }
  const GLsizei n = GLsizei(types.size());
  p.set("uFogCamera", eye);
  glUniform1iv(p.at("uFogType[0]"), n, types.data());
  glUniform4fv(p.at("uFogParams[0]"), n, params.data());
  glUniform3fv(p.at("uFogColor[0]"), n, colors.data());
  if (!lo.empty()) {
    glUniform4fv(p.at("uRegionLo[0]"), n - 1, lo.data());
    glUniform4fv(p.at("uRegionHi[0]"), n - 1, hi.data());
  }
}

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

}  // namespace

Result<Frame> Renderer::Impl::render(const Scene& scene) {
  Stopwatch watch;
  compiled = 0;
  Frame frame;
  if (scene.width < 1 || scene.height < 1 || scene.width > maxTextureSize || scene.height > maxTextureSize)
    return overLimit("/width", "the renderer's largest image side is " + std::to_string(maxTextureSize));
  if (scene.lightning && (scene.lightning->gridWidth < 1 || scene.lightning->gridHeight < 1))
    return invalid("/lightning/grid", "must have at least one cell");
  const View view = viewOf(scene);
  const GLenum mainFormat = scene.bitDepth == 16 && floatBlend ? GL_RGBA32F : GL_RGBA16F;
  Target main;
  if (!main.create(scene.width, scene.height, mainFormat, true))
    return unsatisfiable("/renderer", "the frame buffer cannot be created");
  main.use();
  glClearColor(0, 0, 0, 0);
  glClearDepthf(1);
  glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
  glDisable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glBindVertexArray(emptyVao);
#define TRY(var, expr)              \
  auto var##Result = (expr);        \
  if (!var##Result.ok()) return var##Result.error(); \
  Program& var = *var##Result.value()

  // Backdrop.
  const Background& bg = scene.background;
  const std::string kind = std::to_string(int(bg.kind));
  Texture image;
  if (bg.kind == Background::Kind::kImage) {
    auto data = premultiplied(bg.image);
    image = texture2D(bg.image.width, bg.image.height, GL_RGBA32F, GL_RGBA, GL_FLOAT, data.data(), GL_CLAMP_TO_EDGE);
  }
  {
    TRY(p, program("background:" + kind, screenVertex(), backgroundFragment(bg.kind)));
    glUseProgram(p.id);
    setBackground(p, bg, &image);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    frame.passes.push_back("background");
  }

  // Seed 000 section 2.2: the surface-wave quad, lit through its MikkTSpace frames.
  if (scene.wave) {
    const SurfaceWave& w = *scene.wave;
    if (auto e = ensureWave()) return *e;
    TRY(p, program("wave", waveVertex(), waveFragment()));
    glUseProgram(p.id);
    Vertices mesh(waveVertices, {2, 2, 3, 4}, &waveIndices);
    // Scroll offsets reduced modulo 1 in double: hours of play keep full float precision.
    const double s = w.speed * scene.time;
    auto wrap = [](double x) { return float(x - std::floor(x)); };
    normalA.bind(0), normalB.bind(1), waveAlpha.bind(2);
    p.set("uNormalA", 0), p.set("uNormalB", 1), p.set("uAlpha", 2);
    p.set("uOffsetA", glm::vec2(wrap(s), wrap(0.31 * s)));
    p.set("uOffsetB", glm::vec2(wrap(-0.57 * s), wrap(0.83 * s)));
    p.set("uScale", float(w.scale)), p.set("uStrength", float(w.strength));
    p.set("uLightColor", glm::vec3(w.lightColor)), p.set("uLight", glm::vec3(w.lightDirection));
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE);
    glDrawElements(GL_TRIANGLES, GLsizei(waveIndices.size()), GL_UNSIGNED_INT, nullptr);
    glDisable(GL_BLEND);
    glBindVertexArray(emptyVao);
    frame.passes.push_back("surfaceWave");
  }

  std::optional<FogVariant> fogV;
  if (scene.fog) fogV = fogVariant(*scene.fog);
  const std::string fogKey = fogV ? ":" + fogV->key() : "";

  // Opaque geometry.
  if (!scene.quads.empty()) {
    std::vector<float> data;
    for (const Quad& q : scene.quads) {
      glm::dvec3 n = glm::normalize(q.normal), up = q.up - n * glm::dot(q.up, n);
      if (glm::length(up) < 1e-9) up = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) - n * n.y : glm::dvec3(1, 0, 0) - n * n.x;
      up = glm::normalize(up) * (0.5 * q.size.y);
      glm::dvec3 right = glm::normalize(glm::cross(up, n)) * (0.5 * q.size.x);
      const glm::dvec3 corners[6] = {q.center - right - up, q.center + right - up, q.center + right + up,
                                     q.center - right - up, q.center + right + up, q.center - right + up};
      for (const auto& c : corners)
        data.insert(data.end(), {float(c.x), float(c.y), float(c.z), float(q.color.r), float(q.color.g), float(q.color.b)});
    }
    TRY(p, program("quad" + fogKey, quadVertex(), quadFragment(fogV ? &*fogV : nullptr)));
    glUseProgram(p.id);
    p.set("uViewProjection", view.viewProjection);
    if (scene.fog) setFog(p, *scene.fog, view.eye);
    Vertices mesh(data, {3, 3});
    glEnable(GL_DEPTH_TEST);
    glDrawArrays(GL_TRIANGLES, 0, GLsizei(data.size() / 6));
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(emptyVao);
    frame.passes.push_back(scene.fog ? "quads+fog" : "quads");
  }

  if (scene.bubble) {
    const Bubble& b = *scene.bubble;
    const bubble::Features& f = b.features;
    Texture environment;
    if (f.reflection || f.refraction) {
      // The backdrop as a cube map, so that eqn 8's final vector can look it up.
      environment.make(GL_TEXTURE_CUBE_MAP);
      for (int face = 0; face < 6; ++face)
        glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, GL_RGBA16F, kEnvironmentSize, kEnvironmentSize, 0, GL_RGBA,
                     GL_HALF_FLOAT, nullptr);
      TRY(p, program("environment:" + kind, screenVertex(), environmentFragment(bg.kind)));
      glUseProgram(p.id);
      setBackground(p, bg, &image);
      p.set("uView", glm::mat3(view.view));
      p.set("uTanHalfFov", view.tanHalfFov);
      GLuint fbo = 0;
      glGenFramebuffers(1, &fbo);
      glBindFramebuffer(GL_FRAMEBUFFER, fbo);
      glViewport(0, 0, kEnvironmentSize, kEnvironmentSize);
      for (int face = 0; face < 6; ++face) {
        glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, environment.id, 0);
        p.set("uFace", face);
        glDrawArrays(GL_TRIANGLES, 0, 3);
      }
      glDeleteFramebuffers(1, &fbo);
      main.use();
      frame.passes.push_back("environment");
    }
    std::string key = "bubble:";
    for (bool on : {f.reflection, f.refraction, f.rim, f.textureFlow, f.wobble, f.iridescence}) key += on ? '1' : '0';
    bubble::ShaderSource src = bubble::shader(f, bubble::Glsl::kEs300, fogV ? fogGlsl(*fogV) : "",
                                              fogV ? "  color.rgb = applyFog(color.rgb, vWorld);\n" : "");
    TRY(p, program(key + fogKey, src.vertex, src.fragment));
    glUseProgram(p.id);
    const bubble::Params& bp = b.params;
    const bubble::Film film = bubble::film(bp, b.time);
    p.set("uModel", glm::translate(glm::mat4(1), glm::vec3(b.center)));
    p.set("uViewProjection", view.viewProjection);
    p.set("uWobblePhase", float(bubble::reducedPhase(bp.deltaSpeed, b.time)));
    p.set("uWobbleAmplitude", float(bp.wobbleAmplitude));
    p.set("uBaseColor", glm::vec4(b.baseColor));
    p.set("uCameraPosition", view.eye);
    p.set("uFilmTop", float(film.top));
    p.set("uFilmBottom", float(film.bottom));
    p.set("uEta", float(bp.n1 / bp.n2));
    p.set("uFlowPhase", float(bubble::reducedPhase(bp.betaSpeed, b.time)));
    p.set("uRimPower", float(bp.rimPower));
    p.set("uThickness", float(film.top));
    if (environment.id) environment.bind(0), p.set("uEnvironment", 0);
    Texture flowOwned, thinFilm;
    if (f.textureFlow) flowTexture(b, flowOwned).bind(1), p.set("uFlowTexture", 1);
    if (f.iridescence) {
      thinFilm = texture2D(b.thinFilmWidth, b.thinFilmHeight, GL_RGB32F, GL_RGB, GL_FLOAT, b.thinFilm.data(), GL_CLAMP_TO_EDGE);
      thinFilm.bind(2), p.set("uThinFilm", 2);
    }
    std::vector<float> data;
    data.reserve(b.mesh.positions.size() * 8);
    for (size_t i = 0; i < b.mesh.positions.size(); ++i) {
      const auto &x = b.mesh.positions[i], &n = b.mesh.normals[i];
      const auto& uv = b.mesh.uvs[i];
      data.insert(data.end(), {x.x, x.y, x.z, n.x, n.y, n.z, uv.x, uv.y});
    }
    Vertices mesh(data, {3, 3, 2}, &b.mesh.indices);
    glEnable(GL_DEPTH_TEST);
    glDepthMask(GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    // The near side only: eqns 4-10 are written for the surface facing the viewer.
    glEnable(GL_CULL_FACE);
    glCullFace(GL_BACK);
    glDrawElements(GL_TRIANGLES, GLsizei(b.mesh.indices.size()), GL_UNSIGNED_INT, nullptr);
    glDisable(GL_CULL_FACE);
    glDisable(GL_BLEND);
    glDepthMask(GL_TRUE);
    glDisable(GL_DEPTH_TEST);
    glBindVertexArray(emptyVao);
    frame.passes.push_back(scene.fog ? "bubble+fog" : "bubble");
  }

  if (scene.lightning && !scene.lightning->polylines.empty()) {
    const Lightning& l = *scene.lightning;
    Target core;
    if (!core.create(scene.width, scene.height, GL_RGBA16F, false))
      return unsatisfiable("/renderer", "the lightning buffer cannot be created");
    core.use();
    glClear(GL_COLOR_BUFFER_BIT);
    {
      TRY(p, program("bolt", boltVertex(), boltFragment()));
      glUseProgram(p.id);
      p.set("uSize", glm::vec2(scene.width, scene.height));
      std::vector<float> data = boltGeometry(l, scene.width, scene.height);
      Vertices mesh(data, {2, 3});
      glEnable(GL_BLEND);
      glBlendEquation(GL_MAX);
      glDrawArrays(GL_TRIANGLES, 0, GLsizei(data.size() / 5));
      glBlendEquation(GL_FUNC_ADD);
      glDisable(GL_BLEND);
      glBindVertexArray(emptyVao);
      frame.passes.push_back("lightning");
    }
    const bool glow = l.glowSigma > 0 && l.glowStrength > 0;
    Target blurred, glowTarget;
    if (glow) {
      // Separable Gaussian at half resolution (sigma in half-resolution pixels).
      TRY(p, program("blur", screenVertex(), blurFragment()));
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
      const int hw = (scene.width + 1) / 2, hh = (scene.height + 1) / 2;
      if (!blurred.create(hw, hh, GL_RGBA16F, false) || !glowTarget.create(hw, hh, GL_RGBA16F, false))
        return unsatisfiable("/renderer", "the glow buffers cannot be created");
      p.set("uTargetSize", glm::vec2(hw, hh));
      blurred.use();
      core.color.bind(0);
      p.set("uStep", glm::vec2(1.0f / float(hw), 0));
      glDrawArrays(GL_TRIANGLES, 0, 3);
      frame.passes.push_back("blurHorizontal");
      glowTarget.use();
      blurred.color.bind(0);
      p.set("uStep", glm::vec2(0, 1.0f / float(hh)));
      glDrawArrays(GL_TRIANGLES, 0, 3);
      frame.passes.push_back("blurVertical");
    }
    main.use();
    TRY(p, program(glow ? "composite:glow" : "composite", screenVertex(), compositeFragment(glow)));
    glUseProgram(p.id);
    core.color.bind(0), p.set("uCore", 0);
    if (glow) glowTarget.color.bind(1), p.set("uGlow", 1), p.set("uGlowStrength", float(l.glowStrength));
    p.set("uColor", glm::vec3(l.color));
    glEnable(GL_BLEND);
    glBlendFuncSeparate(GL_ONE, GL_ONE, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_BLEND);
    frame.passes.push_back("lightningComposite");
  }

  if (scene.blend && scene.blend->amount > 0) {  // eqn 12
    TRY(p, program("cameraBlend", screenVertex(), blendFragment()));
    glUseProgram(p.id);
    p.set("uColor", glm::vec3(scene.blend->color));
    p.set("uAmount", float(scene.blend->amount));
    glEnable(GL_BLEND);
    glBlendFunc(GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
    glDrawArrays(GL_TRIANGLES, 0, 3);
    glDisable(GL_BLEND);
    frame.passes.push_back("cameraBlend");
  }
#undef TRY

  // Read back (rows bottom-up in GL), flip, un-premultiply.
  const size_t w = size_t(scene.width), h = size_t(scene.height);
  std::vector<float> pixels(w * h * 4);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glReadPixels(0, 0, scene.width, scene.height, GL_RGBA, GL_FLOAT, pixels.data());
  if (GLenum e = glGetError(); e != GL_NO_ERROR)
    return unsatisfiable("/renderer", "OpenGL error " + std::to_string(e));
  frame.image = Image{scene.width, scene.height, std::vector<float>(w * h * 4)};
  for (size_t y = 0; y < h; ++y) {
    const float* src = &pixels[(h - 1 - y) * w * 4];
    float* dst = &frame.image.rgba[y * w * 4];
    for (size_t x = 0; x < w; ++x, src += 4, dst += 4) {
      float a = std::clamp(src[3], 0.0f, 1.0f);
      for (int c = 0; c < 3; ++c) dst[c] = a > 0 ? std::clamp(src[c] / a, 0.0f, 1.0f) : 0.0f;
      dst[3] = a;
    }
  }
  frame.variantsCompiled = compiled;
  frame.variantsCached = int(programs.size());
  frame.ms = watch.ms();
  return frame;
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
  Impl& m = *r->impl_;
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
  if (!colorFloat) return unsatisfiable("/renderer", m.description + " cannot render to float buffers (GL_EXT_color_buffer_float)");
  glGenVertexArrays(1, &m.emptyVao);
  return r;
}

Result<Frame> Renderer::render(const Scene& scene) { return impl_->render(scene); }
const std::string& Renderer::description() const { return impl_->description; }

}  // namespace effects::render
