// Per-vertex average: each vertex's tangent is the angle-weighted sum of its triangles'
// frames, projected into its normal's plane; handedness by the weighted sign. Never splits.
#include "steps.h"

namespace effects::tangents {
CornerTangents perVertex(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel) {
  const size_t triCount = mesh.indices.size() / 3, vertCount = mesh.positions.size();
  std::vector<Frame> frames(triCount);
  forRange(parallel, triCount, kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t t = begin; t < end; ++t) frames[t] = faceFrame(mesh, t, normals);
  });
  std::vector<dvec3> sum(vertCount, dvec3(0));
  std::vector<double> hand(vertCount, 0.0);
  for (size_t t = 0; t < triCount; ++t) {
    if (frames[t].degenerate) continue;
    for (int c = 0; c < 3; ++c) {
      dvec3 p = trianglePoint(mesh, t, c);
      dvec3 a = normalizeOrZero(trianglePoint(mesh, t, (c + 1) % 3) - p),
            b = normalizeOrZero(trianglePoint(mesh, t, (c + 2) % 3) - p);
      double angle = cornerAngle(a, b);
      uint32_t v = mesh.indices[3 * t + size_t(c)];
      sum[v] += angle * dvec3(frames[t].tangent);
      hand[v] += angle * frames[t].w;
    }
  }
  std::vector<glm::vec4> vertexTangent(vertCount);
  std::vector<uint8_t> vertexFellBack(vertCount, 0);
  for (size_t v = 0; v < vertCount; ++v) {
    dvec3 t = projectToPlane(sum[v], normals[v]);
    const double len = glm::length(t);
    if (len > 1e-9 * glm::length(sum[v]) && len > 0) {
      vertexTangent[v] = glm::vec4(glm::vec3(t / len), hand[v] < 0 ? -1.0f : 1.0f);
    } else {  // no healthy frame around the vertex, or they cancel out
      vertexTangent[v] = fallbackTangent(normals[v]);
      vertexFellBack[v] = 1;
    }
  }
  CornerTangents out;
  out.tangent.resize(mesh.indices.size());
  out.fellBack.resize(mesh.indices.size());
  for (size_t c = 0; c < mesh.indices.size(); ++c) {
    out.tangent[c] = vertexTangent[mesh.indices[c]];
    out.fellBack[c] = vertexFellBack[mesh.indices[c]];
  }
  return out;
}

}  // namespace effects::tangents
