// Conservative voxelisation of triangles for 3-D obstacles: a voxel is blocked when the
// closed triangle and the closed voxel cube intersect, decided by the separating-axis test of
// Akenine-Moller ("Fast 3D Triangle-Box Overlap Testing", 2001): the three box normals, the
// triangle's normal and the nine cross products of edges with box axes.
#include <algorithm>
#include <array>
#include <cmath>
#include <utility>

#include "effects/lightning.h"

namespace effects::lightning {
namespace {

using V3 = std::array<double, 3>;

V3 sub(const V3& a, const V3& b) { return {a[0] - b[0], a[1] - b[1], a[2] - b[2]}; }
V3 cross(const V3& a, const V3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}
double dot(const V3& a, const V3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

// The voxels i along an axis of n whose closed boxes [i, i + 1] can touch [mn, mx], clamped to
// the grid; none when the second is below the first. Doubles: a triangle outside the grid can
// lie 1e33 voxels away, which no int holds.
std::pair<double, double> voxelSpan(double mn, double mx, int n) {
  return {std::max(0.0, std::floor(mn) - 1), std::min(double(n - 1), std::floor(mx))};
}

// Whether the triangle (v0, v1, v2), relative to a box centre, overlaps the box of half side h.
bool overlaps(const V3& v0, const V3& v1, const V3& v2, double h) {
  const V3 e[3] = {sub(v1, v0), sub(v2, v1), sub(v0, v2)};
  const V3 axes[3] = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  // Nine edge x axis directions.
  for (const V3& edge : e)
    for (const V3& axis : axes) {
      const V3 a = cross(edge, axis);
      const double p0 = dot(a, v0), p1 = dot(a, v1), p2 = dot(a, v2);
      const double r = h * (std::fabs(a[0]) + std::fabs(a[1]) + std::fabs(a[2]));
      if (std::min({p0, p1, p2}) > r || std::max({p0, p1, p2}) < -r) return false;
    }
  // The box's own axes (the bounding boxes overlap).
  for (int k = 0; k < 3; ++k)
    if (std::min({v0[size_t(k)], v1[size_t(k)], v2[size_t(k)]}) > h ||
        std::max({v0[size_t(k)], v1[size_t(k)], v2[size_t(k)]}) < -h)
      return false;
  // The triangle's plane.
  const V3 n = cross(e[0], e[1]);
  const double d = dot(n, v0), r = h * (std::fabs(n[0]) + std::fabs(n[1]) + std::fabs(n[2]));
  return std::fabs(d) <= r;
}

}  // namespace

size_t voxelizeTriangles(int width, int height, int depth, const std::vector<double>& positions,
                         const std::vector<uint32_t>& indices, std::vector<uint8_t>& obstacles) {
  size_t tested = 0;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    V3 v[3];
    for (int k = 0; k < 3; ++k) {
      const size_t i = size_t(indices[t + size_t(k)]) * 3;
      v[k] = {positions[i], positions[i + 1], positions[i + 2]};
    }
    int lo[3], hi[3];
    const int size[3] = {width, height, depth};
    bool outside = false;
    for (int a = 0; a < 3; ++a) {
      const double mn = std::min({v[0][size_t(a)], v[1][size_t(a)], v[2][size_t(a)]});
      const double mx = std::max({v[0][size_t(a)], v[1][size_t(a)], v[2][size_t(a)]});
      const auto [l, u] = voxelSpan(mn, mx, size[a]);
      if (!(mx >= 0) || !(mn <= size[a]) || !(u >= l)) {  // tested before converting to int
        outside = true;
        break;
      }
      lo[a] = int(l), hi[a] = int(u);
    }
    if (outside) continue;
    for (int z = lo[2]; z <= hi[2]; ++z)
      for (int y = lo[1]; y <= hi[1]; ++y)
        for (int x = lo[0]; x <= hi[0]; ++x) {
          const size_t i = (size_t(z) * size_t(height) + size_t(y)) * size_t(width) + size_t(x);
          ++tested;
          if (obstacles[i]) continue;
          const V3 c{x + 0.5, y + 0.5, z + 0.5};
          if (overlaps(sub(v[0], c), sub(v[1], c), sub(v[2], c), 0.5)) obstacles[i] = 1;
        }
  }
  return tested;
}

size_t voxelizationWork(int width, int height, int depth, const std::vector<double>& positions,
                        const std::vector<uint32_t>& indices) {
  size_t work = 0;
  const int size[3] = {width, height, depth};
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    size_t voxels = 1;
    for (int a = 0; a < 3; ++a) {
      double mn = INFINITY, mx = -INFINITY;
      for (int k = 0; k < 3; ++k) {
        const double p = positions[size_t(indices[t + size_t(k)]) * 3 + size_t(a)];
        mn = std::min(mn, p), mx = std::max(mx, p);
      }
      const auto [lo, hi] = voxelSpan(mn, mx, size[a]);
      voxels *= hi >= lo ? size_t(hi - lo + 1) : 0;
    }
    work += voxels;
  }
  return work;
}

}  // namespace effects::lightning
