// Normals for the tangent steps: given ones normalised; missing ones angle-weighted over all
// corners at the same position, or flat (every corner its own vertex).
#include <atomic>

#include "steps.h"
#include "weld.h"

namespace effects::tangents {

// A vertex with no usable triangle (or a given normal of zero length) gets +z, counted.
std::vector<dvec3> vertexNormals(const Mesh& mesh, Parallel* parallel, size_t& replaced) {
  const size_t n = mesh.positions.size();
  std::vector<dvec3> out(n, dvec3(0));
  std::atomic<size_t> zero{0};
  if (!mesh.normals.empty()) {
    forRange(parallel, n, kParallelGrain, [&](size_t begin, size_t end) {
      size_t z = 0;
      for (size_t i = begin; i < end; ++i) {
        dvec3 v = normalizeOrZero(dvec3(mesh.normals[i]));
        z += !notZero(v);
        out[i] = notZero(v) ? v : dvec3(0, 0, 1);
      }
      zero += z;
    });
    replaced = zero;
    return out;
  }
  std::vector<uint32_t> at = weld<3>(n, [&](size_t i, float* k) {
    k[0] = mesh.positions[i].x, k[1] = mesh.positions[i].y, k[2] = mesh.positions[i].z;
  });
  std::vector<dvec3> sum(n, dvec3(0));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    dvec3 p[3];
    for (int c = 0; c < 3; ++c) p[c] = dvec3(mesh.positions[mesh.indices[t + c]]);
    dvec3 fn = faceNormal(mesh, t / 3);
    if (!notZero(fn)) continue;
    for (int c = 0; c < 3; ++c) {
      dvec3 a = normalizeOrZero(p[(c + 1) % 3] - p[c]), b = normalizeOrZero(p[(c + 2) % 3] - p[c]);
      if (!notZero(a) || !notZero(b)) continue;
      sum[at[mesh.indices[t + c]]] += cornerAngle(a, b) * fn;
    }
  }
  replaced = 0;
  for (size_t i = 0; i < n; ++i) {
    dvec3 v = normalizeOrZero(sum[at[i]]);
    replaced += !notZero(v);
    out[i] = notZero(v) ? v : dvec3(0, 0, 1);
  }
  return out;
}

Mesh flatExpanded(const Mesh& mesh, std::vector<uint32_t>& cornerToInput) {
  Mesh out;
  const size_t corners = mesh.indices.size();
  out.positions.resize(corners);
  out.uvs.resize(corners);
  out.normals.resize(corners);
  out.indices.resize(corners);
  cornerToInput = mesh.indices;
  for (size_t t = 0; t < corners / 3; ++t) {
    dvec3 fn = faceNormal(mesh, t);
    if (!notZero(fn)) fn = dvec3(0, 0, 1);
    for (size_t c = 3 * t; c < 3 * t + 3; ++c) {
      out.positions[c] = mesh.positions[mesh.indices[c]];
      out.uvs[c] = mesh.uvs[mesh.indices[c]];
      out.normals[c] = glm::vec3(fn);
      out.indices[c] = uint32_t(c);
    }
  }
  return out;
}

}  // namespace effects::tangents
