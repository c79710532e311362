// The steps of tangents::generate (internal to effects/tangents/), one file each:
//   normals.cpp       unit normal per vertex (given, or angle-weighted), flat expansion
//   mikktspace.cpp    MikkTSpace corner tangents (the reference algorithm, ported)
//   per_triangle.cpp  seed 004's per-triangle frame, and corner tangents from it
//   per_vertex.cpp    per-triangle frames angle-averaged per vertex
//   split.cpp         vertices split where their corners' tangents differ
//   tangents.cpp      validation, the order of the steps, stats and the error metric
#pragma once

#include <cstdint>
#include <memory>
#include <new>
#include <utility>
#include <vector>

#include "effects/parallel.h"
#include "effects/tangents.h"
#include "geometry.h"

namespace effects::tangents {

// std::allocator whose resize() leaves new elements default-initialised (for plain data:
// untouched). For buffers a parallel step fills completely: their pages are first touched by
// the threads that fill them, not zeroed beforehand by one thread (100k triangles' MikkTSpace
// buffers are 11 MB of fresh pages a request).
template <class T>
struct NoInit : std::allocator<T> {
  template <class U>
  struct rebind {
    using other = NoInit<U>;
  };
  NoInit() = default;
  template <class U>
  NoInit(const NoInit<U>&) noexcept {}
  template <class U, class... Args>
  void construct(U* p, Args&&... args) {
    if constexpr (sizeof...(Args) == 0)
      ::new (static_cast<void*>(p)) U;
    else
      ::new (static_cast<void*>(p)) U(std::forward<Args>(args)...);
  }
};
template <class T>
using Buffer = std::vector<T, NoInit<T>>;

// A tangent per triangle corner (3 per triangle), and whether it is a fallback.
struct CornerTangents {
  Buffer<glm::vec4> tangent;  // every element written by the step that makes it
  std::vector<uint8_t> fellBack;
};

// Work per chunk when a step splits its loop over the caller's threads (effects/parallel.h).
inline constexpr size_t kParallelGrain = 10000;
// The same for MikkTSpace's vertex groups, each a few corners' worth of projections and angles.
inline constexpr size_t kGroupGrain = 1000;

// A unit normal per vertex: given ones normalised; missing ones angle-weighted over every
// corner at the same position (welded, weld.h); +z where no triangle has area or a given normal
// has zero length (`replaced` counts those vertices).
std::vector<dvec3> vertexNormals(const Mesh& mesh, Parallel* parallel, size_t& replaced);
// Every corner its own vertex with the face normal (glTF's rule for meshes without normals);
// cornerToInput[c] = the input vertex of corner c.
Mesh flatExpanded(const Mesh& mesh, std::vector<uint32_t>& cornerToInput);

struct MikkStats {
  size_t degenerateTriangles = 0, zeroUvArea = 0, groups = 0;
};
CornerTangents mikktspace(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel, MikkStats& stats);

// The frame of triangle t made orthogonal to the normal n.
Frame meshTriangleFrame(const Mesh& mesh, size_t t, const dvec3& n);
// Triangle t's frame with its face normal (the vertex normal of its first corner when the
// triangle has no area, which marks the frame degenerate).
Frame faceFrame(const Mesh& mesh, size_t t, const std::vector<dvec3>& normals);
CornerTangents perTriangle(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel);
CornerTangents perVertex(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel);

// Output vertices: vertex v < n is input vertex v; a vertex whose corners disagree is split.
// Fills out.tangents, out.remap, out.indices.
void splitVertices(const Mesh& mesh, const Buffer<glm::vec4>& corner, const std::vector<dvec3>& normals,
                   Output& out);

}  // namespace effects::tangents
