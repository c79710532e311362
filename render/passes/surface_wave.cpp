// Seed 000 section 2.2: the surface-wave quad, lit through its MikkTSpace frames, two
// scrolling normal maps added over the backdrop, or over a quad of the scene (water).
#include <array>
#include <cmath>

#include "../gpu.h"

namespace effects::render::detail {

std::optional<Error> surfaceWavePass(Gpu& gpu, FrameState& f) {
  const SurfaceWave& w = *f.scene.wave;
  if (auto e = gpu.ensureWave()) return *e;
  const bool world = w.onQuad.has_value();
  const bool fog = world && f.fog.has_value();
  auto program = gpu.program(world ? "wave:world" + (fog ? f.fogKey : "") : "wave", [&] {
    return std::pair{waveVertex(world), waveFragment(world, fog ? &*f.fog : nullptr)};
  });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  // On a quad: its corners in the world, u along its right and v along its up; its tangent
  // frame is its own (T = +u, N out of it), the space the light direction is given in.
  std::vector<float> onQuad;
  if (world) {
    const std::array<glm::dvec3, 4> c = quadCorners(f.scene.quads[*w.onQuad]);
    const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    for (int k = 0; k < 4; ++k)
      onQuad.insert(onQuad.end(), {float(c[size_t(k)].x), float(c[size_t(k)].y), float(c[size_t(k)].z), uv[k][0], uv[k][1],
                                   0, 0, 1, 1, 0, 0, 1});
    p.set("uViewProjection", f.view.viewProjection);
    if (fog) setFog(p, *f.scene.fog, f.view.eye);
  }
  const std::vector<uint32_t> quadIndices = {0, 1, 2, 0, 2, 3};
  Vertices mesh(world ? onQuad : gpu.waveVertices, {world ? 3 : 2, 2, 3, 4}, world ? &quadIndices : &gpu.waveIndices);
  // Scroll offsets reduced modulo 1 in double: hours of play keep full float precision.
  const double s = w.speed * f.scene.time;
  auto wrap = [](double x) { return float(x - std::floor(x)); };
  gpu.normalA.bind(0), gpu.normalB.bind(1), gpu.waveAlpha.bind(2);
  p.set("uNormalA", 0), p.set("uNormalB", 1), p.set("uAlpha", 2);
  p.set("uOffsetA", glm::vec2(wrap(s), wrap(0.31 * s)));
  p.set("uOffsetB", glm::vec2(wrap(-0.57 * s), wrap(0.83 * s)));
  p.set("uScale", float(w.scale)), p.set("uStrength", float(w.strength));
  p.set("uLightColor", glm::vec3(w.lightColor)), p.set("uLight", glm::vec3(w.lightDirection));
  glEnable(GL_BLEND);
  glBlendFunc(GL_ONE, GL_ONE);
  if (world) glEnable(GL_DEPTH_TEST), glDepthFunc(GL_LEQUAL), glDepthMask(GL_FALSE);  // on the quad, behind what hides it
  glDrawElements(GL_TRIANGLES, GLsizei(world ? quadIndices.size() : gpu.waveIndices.size()), GL_UNSIGNED_INT, nullptr);
  if (world) glDisable(GL_DEPTH_TEST), glDepthFunc(GL_LESS), glDepthMask(GL_TRUE);
  glDisable(GL_BLEND);
  glBindVertexArray(gpu.emptyVao);
  f.frame.passes.push_back(world ? "surfaceWave:quad" : "surfaceWave");
  return std::nullopt;
}

}  // namespace effects::render::detail
