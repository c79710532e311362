// Vertex splitting: a vertex keeps its first corner's tangent; a corner with a different one
// (bit for bit) gets a new vertex, shared by later corners with the same tangent.
#include "steps.h"

#include <cstring>

namespace effects::tangents {

void splitVertices(const Mesh& mesh, const Buffer<glm::vec4>& corner, const std::vector<dvec3>& normals,
                   Output& out) {
  const size_t vertCount = mesh.positions.size();
  std::vector<int64_t> nextSplit(vertCount, -1);  // chain of the splits of each input vertex
  std::vector<uint8_t> assigned(vertCount, 0);
  out.tangents.resize(vertCount);
  out.remap.resize(vertCount);
  out.indices.resize(corner.size());
  for (uint32_t v = 0; v < vertCount; ++v) out.remap[v] = v;
  for (size_t c = 0; c < corner.size(); ++c) {
    uint32_t v = mesh.indices[c];
    if (!assigned[v]) {
      assigned[v] = 1;
      out.tangents[v] = corner[c];
      out.indices[c] = v;
      continue;
    }
    int64_t k = v, last = v;
    while (k >= 0 && std::memcmp(&out.tangents[size_t(k)], &corner[c], sizeof(glm::vec4)) != 0) {
      last = k;
      k = nextSplit[size_t(k)];
    }
    if (k < 0) {
      k = int64_t(out.tangents.size());
      out.tangents.push_back(corner[c]);
      out.remap.push_back(v);
      nextSplit.push_back(-1);
      nextSplit[size_t(last)] = k;
    }
    out.indices[c] = uint32_t(k);
  }
  for (uint32_t v = 0; v < vertCount; ++v)  // vertices no triangle uses
    if (!assigned[v]) out.tangents[v] = fallbackTangent(normals[v]);
}

}  // namespace effects::tangents
