// Seed 000's soap bubble: the backdrop rendered into a cube map (what eqn 8's final vector
// looks up), then the near side of the sphere, blended over the frame.
#include <glm/gtc/matrix_transform.hpp>

#include "../gpu.h"

namespace effects::render::detail {
namespace {

// The backdrop as a cube map, so that eqn 8's final vector can look it up.
std::optional<Error> environmentCube(Gpu& gpu, FrameState& f, Texture& environment) {
  const Background& bg = f.scene.background;
  environment.make(GL_TEXTURE_CUBE_MAP);
  for (int face = 0; face < 6; ++face)
    glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, GL_RGBA16F, kEnvironmentSize, kEnvironmentSize, 0, GL_RGBA,
                 GL_HALF_FLOAT, nullptr);
  auto program =
      gpu.program("environment:" + std::to_string(int(bg.kind)), screenVertex(), environmentFragment(bg.kind));
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  setBackground(p, bg, &f.backgroundImage);
  p.set("uView", glm::mat3(f.view.view));
  p.set("uTanHalfFov", f.view.tanHalfFov);
  GLuint fbo = 0;
  glGenFramebuffers(1, &fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, kEnvironmentSize, kEnvironmentSize);
  for (int face = 0; face < 6; ++face) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, environment.id,
                           0);
    p.set("uFace", face);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  glDeleteFramebuffers(1, &fbo);
  f.main.use();
  f.frame.passes.push_back("environment");
  return std::nullopt;
}

// The program's cache key: one bit per feature, in the order of bubble::Features.
std::string programKey(const bubble::Features& features) {
  std::string key = "bubble:";
  for (bool on : {features.reflection, features.refraction, features.rim, features.textureFlow, features.wobble,
                  features.iridescence})
    key += on ? '1' : '0';
  return key;
}

// Every uniform of the bubble's program but the textures (a disabled feature's is ignored).
void setUniforms(Program& p, const Bubble& b, const FrameState& f) {
  const bubble::Params& bp = b.params;
  const bubble::Film film = bubble::film(bp, b.time);
  p.set("uModel", glm::translate(glm::mat4(1), glm::vec3(b.center)));
  p.set("uViewProjection", f.view.viewProjection);
  p.set("uWobblePhase", float(bubble::reducedPhase(bp.deltaSpeed, b.time)));
  p.set("uWobbleAmplitude", float(bp.wobbleAmplitude));
  p.set("uBaseColor", glm::vec4(b.baseColor));
  p.set("uCameraPosition", f.view.eye);
  p.set("uFilmTop", float(film.top));
  p.set("uFilmBottom", float(film.bottom));
  p.set("uEta", float(bp.n1 / bp.n2));
  p.set("uFlowPhase", float(bubble::reducedPhase(bp.betaSpeed, b.time)));
  p.set("uRimPower", float(bp.rimPower));
  p.set("uThickness", float(film.top));
}

// The mesh's vertices interleaved as the program reads them: position, normal, uv.
std::vector<float> interleaved(const bubble::Mesh& m) {
  std::vector<float> data;
  data.reserve(m.positions.size() * 8);
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const auto &x = m.positions[i], &n = m.normals[i];
    const auto& uv = m.uvs[i];
    data.insert(data.end(), {x.x, x.y, x.z, n.x, n.y, n.z, uv.x, uv.y});
  }
  return data;
}

// Draws the bound mesh blended over the frame, depth-tested without writing depth.
void drawNearSide(GLsizei indexCount) {
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
  // The near side only: eqns 4-10 are written for the surface facing the viewer.
  glEnable(GL_CULL_FACE);
  glCullFace(GL_BACK);
  glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
  glDisable(GL_CULL_FACE);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDisable(GL_DEPTH_TEST);
}

}  // namespace

std::optional<Error> bubblePass(Gpu& gpu, FrameState& f) {
  const Bubble& b = *f.scene.bubble;
  const bubble::Features& features = b.features;
  Texture environment;
  if (features.reflection || features.refraction)
    if (auto e = environmentCube(gpu, f, environment)) return e;
  bubble::ShaderSource src = bubble::shader(features, bubble::Glsl::kEs300, f.fog ? fogGlsl(*f.fog) : "",
                                            f.fog ? "  color.rgb = applyFog(color.rgb, vWorld);\n" : "");
  auto program = gpu.program(programKey(features) + f.fogKey, src.vertex, src.fragment);
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  setUniforms(p, b, f);
  if (environment.id) environment.bind(0), p.set("uEnvironment", 0);
  Texture flowOwned, thinFilm;
  if (features.textureFlow) gpu.flowTexture(b, flowOwned).bind(1), p.set("uFlowTexture", 1);
  if (features.iridescence) {
    thinFilm =
        texture2D(b.thinFilmWidth, b.thinFilmHeight, GL_RGB32F, GL_RGB, GL_FLOAT, b.thinFilm.data(), GL_CLAMP_TO_EDGE);
    thinFilm.bind(2), p.set("uThinFilm", 2);
  }
  Vertices mesh(interleaved(b.mesh), {3, 3, 2}, &b.mesh.indices);
  drawNearSide(GLsizei(b.mesh.indices.size()));
  glBindVertexArray(gpu.emptyVao);
  f.frame.passes.push_back(f.scene.fog ? "bubble+fog" : "bubble");
  return std::nullopt;
}

}  // namespace effects::render::detail
