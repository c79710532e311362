// Seed 000 section 2.2: the surface-wave quad, lit through its MikkTSpace frames, two
// scrolling normal maps added over the backdrop.
#include <cmath>

#include "../gpu.h"

namespace effects::render::detail {

std::optional<Error> surfaceWavePass(Gpu& gpu, FrameState& f) {
  const SurfaceWave& w = *f.scene.wave;
  if (auto e = gpu.ensureWave()) return *e;
  auto program = gpu.program("wave", [] { return std::pair{waveVertex(), waveFragment()}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  Vertices mesh(gpu.waveVertices, {2, 2, 3, 4}, &gpu.waveIndices);
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
  glDrawElements(GL_TRIANGLES, GLsizei(gpu.waveIndices.size()), GL_UNSIGNED_INT, nullptr);
  glDisable(GL_BLEND);
  glBindVertexArray(gpu.emptyVao);
  f.frame.passes.push_back("surfaceWave");
  return std::nullopt;
}

}  // namespace effects::render::detail
