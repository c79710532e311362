// The per-context GPU state: program cache, textures made once.
#include "gpu.h"

namespace effects::render::detail {

Gpu::~Gpu() {
  if (egl.context) {
    for (auto& p : programs) glDeleteProgram(p.second.id);
    if (emptyVao) glDeleteVertexArrays(1, &emptyVao);
    normalA = Texture(), normalB = Texture(), waveAlpha = Texture(), defaultFlow = Texture();
    for (Target* t : {&main, &resolved, &boltCore, &blurred, &glow}) t->release();
    for (int i = 0; i < 3; ++i) apsfBlurred[i].release(), apsfGlow[i].release();
    environment = Texture();
    thinFilms.entries.clear(), spheres.entries.clear();
    if (environmentFbo) glDeleteFramebuffers(1, &environmentFbo);
    destroyContext(egl);
  }
}

Result<Program*> Gpu::compileProgram(const std::string& key, const std::string& vs, const std::string& fs) {
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

const Texture& Gpu::flowTexture(const Bubble& b, Texture& owned) {
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

std::optional<Error> Gpu::ensureWave() {
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

}  // namespace effects::render::detail
