// Small vector helpers shared by the tangent steps (internal to effects/tangents/).
#pragma once

#include <cmath>

#include <glm/geometric.hpp>

#include "effects/tangents.h"

namespace effects::tangents {

using glm::dvec2;
using glm::dvec3;

inline bool notZero(const dvec3& v) { return glm::dot(v, v) > 1e-300; }
inline dvec3 normalizeOrZero(const dvec3& v) {
  double l = glm::length(v);
  return l > 0 && std::isfinite(l) ? v / l : dvec3(0);
}
inline dvec3 projectToPlane(const dvec3& v, const dvec3& n) { return v - glm::dot(n, v) * n; }

// The x axis projected into the plane of unit `n`; when n lies along x, the world axis least
// aligned with n, projected.
inline dvec3 inPlaneAxis(const dvec3& n) {
  dvec3 t = projectToPlane(dvec3(1, 0, 0), n);
  if (glm::length(t) > 1e-6) return glm::normalize(t);
  dvec3 a = std::abs(n.y) <= std::abs(n.z) ? dvec3(0, 1, 0) : dvec3(0, 0, 1);
  return glm::normalize(projectToPlane(a, n));
}

// Angle at a corner between the (unnormalised) edges a and b, robust near 0 and pi.
inline double cornerAngle(const dvec3& a, const dvec3& b) {
  return std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
}

inline dvec3 trianglePoint(const Mesh& m, size_t t, int c) { return dvec3(m.positions[m.indices[3 * t + size_t(c)]]); }
// Unit face normal of triangle t, zero when its area is zero.
inline dvec3 faceNormal(const Mesh& m, size_t t) {
  return normalizeOrZero(
      glm::cross(trianglePoint(m, t, 1) - trianglePoint(m, t, 0), trianglePoint(m, t, 2) - trianglePoint(m, t, 0)));
}

// Where no frame exists (no UV-valid triangle at the vertex) the reference emits its default
// (1, 0, 0) with w = -1, which is not orthogonal to N; effectd emits that default projected
// into N's plane, so it stays the nearest valid tangent to what every MikkTSpace tool writes.
inline glm::vec4 fallbackTangent(const dvec3& n) { return {glm::vec3(inPlaneAxis(n)), -1.0f}; }

}  // namespace effects::tangents
