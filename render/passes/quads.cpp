// Opaque quads (walls, floors, props) with the depth test, fogged per fragment when the
// scene has fog (fog.cpp).
#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>

#include <glm/geometric.hpp>

#include "../fog.h"
#include "../gpu.h"

namespace effects::render {

namespace detail {

std::array<glm::dvec3, 4> quadCorners(const Quad& q) {
  glm::dvec3 n = glm::normalize(q.normal), up = q.up - n * glm::dot(q.up, n);
  if (glm::length(up) < 1e-9) up = std::abs(n.y) < 0.9 ? glm::dvec3(0, 1, 0) - n * n.y : glm::dvec3(1, 0, 0) - n * n.x;
  up = glm::normalize(up) * (0.5 * q.size.y);
  const glm::dvec3 right = glm::normalize(glm::cross(up, n)) * (0.5 * q.size.x);
  return {q.center - right - up, q.center + right - up, q.center + right + up, q.center - right + up};
}

std::optional<Error> quadsPass(Gpu& gpu, FrameState& f) {
  const Scene& scene = f.scene;
  std::vector<float> data;
  for (const Quad& q : scene.quads) {
    const std::array<glm::dvec3, 4> c = quadCorners(q);
    for (int k : {0, 1, 2, 0, 2, 3})
      data.insert(data.end(),
                  {float(c[k].x), float(c[k].y), float(c[k].z), float(q.color.r), float(q.color.g), float(q.color.b)});
  }
  auto program = gpu.program("quad" + f.fogKey,
                             [&] { return std::pair{quadVertex(), quadFragment(f.fog ? &*f.fog : nullptr)}; });
  if (!program.ok()) return program.error();
  Program& p = *program.value();
  glUseProgram(p.id);
  p.set("uViewProjection", f.view.viewProjection);
  if (scene.fog) setFog(p, *scene.fog, f.view.eye);
  Vertices mesh(data, {3, 3});
  glEnable(GL_DEPTH_TEST);
  glDrawArrays(GL_TRIANGLES, 0, GLsizei(data.size() / 6));
  glDisable(GL_DEPTH_TEST);
  glBindVertexArray(gpu.emptyVao);
  f.frame.passes.push_back(scene.fog ? "quads+fog" : "quads");
  return std::nullopt;
}

}  // namespace detail
}  // namespace effects::render
