// The bubble: the backdrop rendered into a cube map (what the film's mirror direction and eqn
// 8's final vector look up), then the sphere blended over the frame (the soap film: far side,
// then near side, premultiplied; seed 000's model: the near side).
#include <algorithm>

#include <glm/geometric.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include "../gpu.h"

namespace effects::render::detail {
namespace {

// The backdrop as a cube map, so that eqn 8's final vector can look it up.
// The cube (Gpu::environment) is made once per render thread and drawn again every frame.
std::optional<Error> environmentCube(Gpu& gpu, FrameState& f) {
  const Background& bg = f.scene.background;
  Texture& environment = gpu.environment;
  if (!environment.id) {
    environment.make(GL_TEXTURE_CUBE_MAP);
    for (int face = 0; face < 6; ++face)
      glTexImage2D(GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, 0, GL_RGBA16F, kEnvironmentSize, kEnvironmentSize, 0,
                   GL_RGBA, GL_HALF_FLOAT, nullptr);
    glGenFramebuffers(1, &gpu.environmentFbo);
  }
  const std::optional<Environment>& sky = f.scene.environment;
  auto program = gpu.program("environment:" + (sky ? std::string("sky") : std::to_string(int(bg.kind))), [&] {
    return std::pair{screenVertex(), environmentFragment(bg.kind, sky.has_value())};
  });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  if (sky) {
    p.set("uZenith", glm::vec3(sky->zenith));
    p.set("uHorizon", glm::vec3(sky->horizon));
    p.set("uGround", glm::vec3(sky->ground));
  } else {
    setBackground(p, bg, &f.backgroundImage);
  }
  p.set("uView", glm::mat3(f.view.view));
  p.set("uTanHalfFov", f.view.tanHalfFov);
  glBindFramebuffer(GL_FRAMEBUFFER, gpu.environmentFbo);
  glViewport(0, 0, kEnvironmentSize, kEnvironmentSize);
  for (int face = 0; face < 6; ++face) {
    glFramebufferTexture2D(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_CUBE_MAP_POSITIVE_X + face, environment.id,
                           0);
    p.set("uFace", face);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  }
  f.main.use();
  f.frame.passes.push_back("environment");
  return std::nullopt;
}

// Every uniform of the bubble's program but the textures (a disabled feature's is ignored).
void setUniforms(Program& p, const Bubble& b, const FrameState& f) {
  const bubble::Params& bp = b.params;
  const bubble::Film film = bubble::film(bp, b.time);
  const bubble::WobbleShape wobble = bubble::wobbleInObject(bp, b.radius);
  p.set("uModel", glm::translate(glm::mat4(1), glm::vec3(b.center)));
  p.set("uViewProjection", f.view.viewProjection);
  p.set("uWobblePhase", float(bubble::reducedPhase(bp.deltaSpeed, b.time)));
  p.set("uWobbleAmplitude", float(wobble.amplitude));
  p.set("uWobbleFrequency", float(wobble.frequency));
  p.set("uBaseColor", glm::vec4(b.baseColor));
  p.set("uCameraPosition", f.view.eye);
  p.set("uFilmTop", float(film.top));
  p.set("uFilmBottom", float(film.bottom));
  p.set("uEta", float(bp.n1 / bp.n2));
  p.set("uFlowPhase", float(bubble::reducedPhase(bp.betaSpeed, b.time)));
  p.set("uRimPower", float(bp.rimPower));
  p.set("uThickness", float(film.top));
  p.set("uThicknessRange", glm::vec2(b.thinFilmRangeNm));
  p.set("uThicknessNm", float(bubble::equatorThickness(bp, b.film, b.time)));
  const int lights = int(std::min<size_t>(b.lights.size(), bubble::kMaxLights));
  p.set("uLightCount", lights);
  for (int i = 0; i < lights; ++i) {
    const bubble::Light& l = b.lights[size_t(i)];
    const std::string at = "[" + std::to_string(i) + "]";
    p.set("uLightDirection" + at, glm::vec3(glm::normalize(l.direction)));
    p.set("uLightRadiance" + at, glm::vec3(l.color * l.intensity));
    p.set("uLightSharpness" + at, float(bubble::highlightSharpness(l)));
  }
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

// Draws the bound mesh over the frame, depth-tested without writing depth: the paper's near
// side with straight alpha; the film's far side (seen through the near one) first when the
// feature is on, each side twice: what passes through it (multiplied), then what it reflects
// (added).
void drawMesh(Program& p, const bubble::Features& f, GLsizei indexCount) {
  glEnable(GL_DEPTH_TEST);
  glDepthMask(GL_FALSE);
  glEnable(GL_BLEND);
  glEnable(GL_CULL_FACE);
  auto draw = [&](GLenum cull) {
    glCullFace(cull);
    if (f.shading == bubble::Shading::kPaper) {
      glBlendFuncSeparate(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA, GL_ONE, GL_ONE_MINUS_SRC_ALPHA);
      glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
      return;
    }
    p.set("uPass", 0);
    glBlendFuncSeparate(GL_ZERO, GL_SRC_COLOR, GL_ZERO, GL_SRC_ALPHA);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
    p.set("uPass", 1);
    glBlendFunc(GL_ONE, GL_ONE);
    glDrawElements(GL_TRIANGLES, indexCount, GL_UNSIGNED_INT, nullptr);
  };
  if (f.shading == bubble::Shading::kFilm && f.backFace) draw(GL_FRONT);
  draw(GL_BACK);  // eqns 4-10 are written for the surface facing the viewer
  glDisable(GL_CULL_FACE);
  glBlendFunc(GL_ONE, GL_ZERO);
  glDisable(GL_BLEND);
  glDepthMask(GL_TRUE);
  glDisable(GL_DEPTH_TEST);
}

// Fog over the bubble: straight alpha mixes; the film fogs the light it reflects and adds the
// fog's own colour in proportion to the light it stops (applyFog is affine in the colour:
// mix(fog, rgb, f)); what passes through it was fogged where it came from.
std::string fogFinish(const bubble::Features& f) {
  if (f.shading == bubble::Shading::kPaper) return "  color.rgb = applyFog(color.rgb, vWorld);\n";
  return "  if (uPass != 0) {\n"
         "    vec3 fogged0 = applyFog(vec3(0.0), vWorld);\n"
         "    color.rgb = color.rgb * (applyFog(vec3(1.0), vWorld) - fogged0) + (uPass == 1 ? R : vec3(color.a)) * "
         "fogged0;\n"
         "  }\n";
}

// One bubble over the frame with the environment cube bound to unit 0.
std::optional<Error> drawBubble(Gpu& gpu, FrameState& f, const Bubble& b) {
  const bubble::Features& features = b.features;
  const bool film = features.shading == bubble::Shading::kFilm;
  auto program = gpu.program("bubble:" + bubble::variantKey(features) + f.fogKey, [&] {
    bubble::ShaderSource src = bubble::shader(features, bubble::Glsl::kEs300, f.fog ? fog::shaderGlsl(*f.fog) : "",
                                              f.fog ? fogFinish(features) : "");
    return std::pair{src.vertex, src.fragment};
  });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  setUniforms(p, b, f);
  if (f.scene.fog) setFog(p, *f.scene.fog, f.view.eye);
  // Made first, bound after: making a texture binds it to the active unit.
  Texture flowOwned, thickness;
  const Texture* thinFilm = nullptr;
  if ((film || features.iridescence) && b.thinFilm)
    thinFilm = &gpu.thinFilms.get(b.thinFilm, [&] {
      const bubble::ThinFilmTable& t = *b.thinFilm;
      return std::make_unique<Texture>(
          texture2D(t.width, t.height, GL_RGB16F, GL_RGB, GL_FLOAT, t.rgb.data(), GL_CLAMP_TO_EDGE));
    });
  if (film && features.thickness) {  // 16F filters everywhere (32F needs an extension)
    const bool prepared = b.thickness && b.thicknessTime == b.time;
    std::optional<bubble::ThicknessField> own;  // computed here when the scene came without it
    if (!prepared) {
      auto field = thicknessOf(b, nullptr);
      if (!field.ok()) return field.error();
      own = std::move(field.value());
    }
    const bubble::ThicknessField& t = prepared ? *b.thickness : *own;
    thickness = texture2D(t.width, t.height, GL_R16F, GL_RED, GL_FLOAT, t.nm.data());
    glTexParameteri(GL_TEXTURE_2D, GL_TEXTURE_WRAP_T, GL_CLAMP_TO_EDGE);
  }
  const Texture* flow = !film && features.textureFlow ? &gpu.flowTexture(b, flowOwned) : nullptr;
  p.set("uEnvironment", 0);
  if (flow) flow->bind(1), p.set("uFlowTexture", 1);
  if (thinFilm) thinFilm->bind(2), p.set("uThinFilm", 2);
  if (thickness.id) thickness.bind(3), p.set("uThicknessField", 3);
  const Vertices& mesh = gpu.spheres.get(b.mesh, [&] {
    return std::make_unique<Vertices>(interleaved(*b.mesh), std::vector<int>{3, 3, 2}, &b.mesh->indices,
                                      GL_STATIC_DRAW);
  });
  glBindVertexArray(mesh.vao);
  drawMesh(p, features, GLsizei(b.mesh->indices.size()));
  glBindVertexArray(gpu.emptyVao);
  f.frame.passes.push_back(std::string(film ? "bubble-film" : "bubble") + (f.scene.fog ? "+fog" : ""));
  return std::nullopt;
}

}  // namespace

std::optional<Error> bubblePass(Gpu& gpu, FrameState& f) {
  bool needsEnvironment = false;
  for (const Bubble& b : f.scene.bubbles)
    needsEnvironment |= b.features.shading == bubble::Shading::kFilm || b.features.reflection || b.features.refraction;
  if (needsEnvironment)  // one cube for every bubble
    if (auto e = environmentCube(gpu, f)) return e;
  // Far to near, so each is blended over those behind it.
  std::vector<const Bubble*> order;
  for (const Bubble& b : f.scene.bubbles) order.push_back(&b);
  const glm::dvec3 eye(f.view.eye);
  std::stable_sort(order.begin(), order.end(), [&](const Bubble* a, const Bubble* b) {
    return glm::length(a->center - eye) > glm::length(b->center - eye);
  });
  for (const Bubble* b : order) {
    if (needsEnvironment) gpu.environment.bind(0);
    if (auto e = drawBubble(gpu, f, *b)) return e;
  }
  return std::nullopt;
}

}  // namespace effects::render::detail

namespace effects::render {

Result<bubble::ThicknessField> thicknessOf(const Bubble& b, Parallel* parallel) {
  bubble::ThicknessOptions o = b.film;
  o.measureError = false;  // the request's answer measures it; a frame only draws
  return bubble::thicknessField(b.params, o, b.time, parallel);
}

std::optional<Error> prepareThickness(Bubble& b, Parallel* parallel) {
  b.thickness.reset();
  if (b.features.shading != bubble::Shading::kFilm || !b.features.thickness) return std::nullopt;
  auto field = thicknessOf(b, parallel);
  if (!field.ok()) return field.error();
  b.thickness = std::move(field.value());
  b.thicknessTime = b.time;
  return std::nullopt;
}

}  // namespace effects::render
