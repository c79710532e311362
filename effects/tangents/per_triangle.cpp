// Seed 004's per-triangle TBN: T and B from the triangle's edges and UV deltas, Gram-Schmidt
// against the normal, handedness from the sign of (N x T) . B.
#include "steps.h"

namespace effects::tangents {
Frame triangleFrame(const dvec3 p[3], const dvec2 uv[3], const dvec3& nIn) {
  Frame f;
  dvec3 n = normalizeOrZero(nIn);
  if (!notZero(n)) n = dvec3(0, 0, 1);
  dvec3 e0 = p[1] - p[0], e1 = p[2] - p[0];
  double u0 = uv[1].x - uv[0].x, u1 = uv[2].x - uv[0].x, v0 = uv[1].y - uv[0].y, v1 = uv[2].y - uv[0].y;
  double det = u0 * v1 - v0 * u1;
  double scale = (std::abs(u0) + std::abs(v0)) * (std::abs(u1) + std::abs(v1));
  // [T; B] = inverse([u0 v0; u1 v1]) [e0; e1]. Only directions matter after Gram-Schmidt, so
  // the 1/det is replaced by its sign: no overflow for tiny determinants or huge coordinates.
  double s = det < 0 ? -1.0 : 1.0;
  dvec3 tRaw = s * (v1 * e0 - v0 * e1);
  dvec3 bRaw = s * (u0 * e1 - u1 * e0);
  dvec3 t = projectToPlane(normalizeOrZero(tRaw), n);
  if (std::abs(det) > 1e-12 * scale && glm::length(t) > 1e-6) {
    t = glm::normalize(t);                                      // T = normalize(T - (N.T) N)
    f.w = glm::dot(glm::cross(n, t), bRaw) < 0 ? -1.0f : 1.0f;  // handedness
  } else {
    f.degenerate = true;  // the same default as MikkTSpace's, in N's plane
    glm::vec4 d = fallbackTangent(n);
    t = dvec3(d);
    f.w = d.w;
  }
  f.tangent = glm::vec3(t);
  f.bitangent = glm::vec3(double(f.w) * glm::cross(n, t));  // B = normalize(N x T), signed
  f.normal = glm::vec3(n);
  return f;
}

Frame meshTriangleFrame(const Mesh& mesh, size_t t, const dvec3& n) {
  dvec3 p[3];
  dvec2 uv[3];
  for (int c = 0; c < 3; ++c) {
    p[c] = trianglePoint(mesh, t, c);
    uv[c] = dvec2(mesh.uvs[mesh.indices[3 * t + size_t(c)]]);
  }
  return triangleFrame(p, uv, n);
}

Frame faceFrame(const Mesh& mesh, size_t t, const std::vector<dvec3>& normals) {
  const dvec3 fn = faceNormal(mesh, t);
  Frame f = meshTriangleFrame(mesh, t, notZero(fn) ? fn : normals[mesh.indices[3 * t]]);
  if (!notZero(fn)) f.degenerate = true;
  return f;
}

// Each corner: its triangle's frame, made orthogonal to the corner's own normal.
CornerTangents perTriangle(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel) {
  CornerTangents out;
  out.tangent.resize(mesh.indices.size());
  out.fellBack.assign(mesh.indices.size(), 0);
  forRange(parallel, mesh.indices.size(), kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t c = begin; c < end; ++c) {
      Frame f = meshTriangleFrame(mesh, c / 3, normals[mesh.indices[c]]);
      out.tangent[c] = glm::vec4(f.tangent, f.w);
      out.fellBack[c] = f.degenerate;
    }
  });
  return out;
}

}  // namespace effects::tangents
