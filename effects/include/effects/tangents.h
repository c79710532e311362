// effects/tangents.h — tangent frames for normal mapping.
//
// Source: seed 004 ("Bump Mapping": per-triangle TBN from the edge / UV-delta system, then
// Gram-Schmidt), and MikkTSpace (Mikkelsen 2008, the reference implementation mikktspace.c
// that Blender, Unity, Unreal and glTF use). Digest: docs/effects.md section 4.
//
// Modes:
//   kMikkTSpace   the reference algorithm, step for step: vertices welded on identical
//                 (position, normal, uv); triangles with coincident corners set aside and
//                 given their neighbours' frames afterwards; per-triangle frames grouped
//                 around each vertex over edge-adjacent triangles of the same UV orientation;
//                 angle-weighted average of the frames projected into the normal's plane.
//   kPerTriangle  seed 004: [u0 v0; u1 v1][T; B] = [e0; e1], T = normalize(T - (N.T)N),
//                 B = normalize(N x T), w = sign((N x T) . B_raw), at every corner with that
//                 corner's normal. Flat per triangle, so corners of a vertex rarely agree.
//   kPerVertex    the classic per-vertex average (Lengyel 2001): each triangle's frame
//                 (against its face normal) summed at its vertices weighted by the corner
//                 angle, then Gram-Schmidt against the vertex normal; w = sign of the
//                 weighted handedness sum. One tangent per input vertex: nothing is split, so
//                 mirrored UV seams get an averaged (wrong) tangent — the price of no splits.
//
// Output is per vertex: a vertex whose corners get different tangents is split, so the output
// can have more vertices than the input. `remap[k]` is the input vertex of output vertex k;
// the first n output vertices are the n input vertices in order, splits are appended.
// Bitangent = w * cross(N, T) (glTF / MikkTSpace convention).
//
// Degenerate input has defined, finite output: every tangent is unit length and orthogonal
// to its normal within 1e-5. Where MikkTSpace leaves no frame (UV area 0 with no healthy
// neighbour, a vertex only on coincident-corner triangles, an unused vertex) it emits the
// placeholder (1, 0, 0), w = -1, which is not orthogonal to N; effectd emits that placeholder
// projected into N's plane (the y axis if N is along x), w = -1. kPerTriangle uses the same
// for a zero UV determinant. Computation is in double, so coordinates of 1e20 or 1e-20
// neither overflow nor underflow. Non-finite input is rejected naming the index.
//
// Normals: given ones are normalised; missing ones are computed (kSmooth: angle-weighted
// face normals summed over all corners at the same position, so UV seams stay smooth;
// kFlat: the face normal at each corner, as glTF mandates for primitives without normals).
// Thread-safety: pure functions, reentrant.
#pragma once

#include <cstddef>
#include <cstdint>
#include <optional>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "effects/common.h"
#include "effects/parallel.h"

#include "effects/export.h"

EFFECTS_API_BEGIN
namespace effects::tangents {

enum class Mode { kMikkTSpace, kPerTriangle, kPerVertex };
enum class NormalRule { kSmooth, kFlat };  // how missing normals are computed

const char* toString(Mode mode);

struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;  // empty, or one per position
  std::vector<glm::vec2> uvs;      // one per position
  std::vector<uint32_t> indices;   // three per triangle, counter-clockwise = front
};

struct Options {
  Mode mode = Mode::kMikkTSpace;
  NormalRule missingNormals = NormalRule::kSmooth;
  bool measureError = false;    // kPerTriangle/kPerVertex: angle error against MikkTSpace (runs both)
  bool triangleFrames = false;  // also return the per-triangle TBN with the face normal
  size_t maxVertices = 2'000'000, maxTriangles = 4'000'000;
  Parallel* parallel = nullptr;  // where the steps may split their work; null = this thread only
};

struct Frame {
  glm::vec3 tangent{1, 0, 0}, bitangent{0, 1, 0}, normal{0, 0, 1};
  float w = 1;
  bool degenerate = false;  // UV determinant or area 0: fallback tangent
};

struct Output {
  std::vector<glm::vec4> tangents;    // per output vertex: xyz unit, w = +-1
  std::vector<glm::vec3> normals;     // per output vertex, unit (given, or computed)
  std::vector<uint32_t> remap;        // output vertex -> input vertex
  std::vector<uint32_t> indices;      // the triangles over output vertices
  std::vector<Frame> triangleFrames;  // when Options::triangleFrames
  Stats stats;                        // counters: triangles, inputVertices, outputVertices, degenerateTriangles,
                // zeroUvAreaTriangles, groups; kPerTriangle/kPerVertex + measureError: error = mean angle
                // (degrees) to MikkTSpace, counters maxAngleDeg, handednessMismatches
};

// Field errors: "/positions/<i>", "/normals/<i>", "/uvs/<i>", "/indices/<i>" (element index),
// counts and limits ("/indices", "/uvs", "/normals", "/positions").
[[nodiscard]] std::optional<Error> validate(const Mesh& mesh, const Options& options);

Result<Output> generate(const Mesh& mesh, const Options& options);

// The note's per-triangle frame with normal n (not necessarily the face normal).
Frame triangleFrame(const glm::dvec3 p[3], const glm::dvec2 uv[3], const glm::dvec3& n);

// Angle in degrees between two tangents' xyz (0 when both are equal).
double angleDeg(const glm::vec4& a, const glm::vec4& b);

}  // namespace effects::tangents
EFFECTS_API_END
