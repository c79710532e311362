// Seed 002 eqn 4 in 3-D: the boundary potential of the shell around a voxel grid and of its
// obstacle voxels, by a Barnes-Hut octree (boundary_map.h: VolumeBoundary).
#include <algorithm>
#include <cmath>

#include "boundary_map.h"
#include "hooks.h"

namespace effects::lightning {
namespace detail {

namespace {
constexpr double kTheta = 0.5;  // opening angle: a block of side s counts as one charge at r >= s / theta
constexpr int kLeaf = 4;        // voxels per side of the smallest stored block
}  // namespace

VolumeBoundary::VolumeBoundary(int width, int height, int depth, const std::vector<uint8_t>* obstacles)
    : dw_(width + 2),
      dh_(height + 2),
      dd_(depth + 2),
      w_(width),
      h_(height),
      memoVoxels_(size_t(width) * size_t(height) * size_t(depth) <= kMemoVoxels
                      ? size_t(width) * size_t(height) * size_t(depth)
                      : 0),
      memo_(memoVoxels_) {
  Level l{(dw_ + kLeaf - 1) / kLeaf, (dh_ + kLeaf - 1) / kLeaf, (dd_ + kLeaf - 1) / kLeaf, {}, {}, {}, {}};
  const size_t n = size_t(l.w) * size_t(l.h) * size_t(l.d);
  for (auto* v : {&l.count, &l.cx, &l.cy, &l.cz}) v->assign(n, 0.0f);
  leafCharges_.assign(n, 0);
  auto put = [&](int x, int y, int z) {  // domain coordinates
    const size_t b = (size_t(z / kLeaf) * size_t(l.h) + size_t(y / kLeaf)) * size_t(l.w) + size_t(x / kLeaf);
    const uint64_t bit = uint64_t(1) << (((z % kLeaf) * kLeaf + y % kLeaf) * kLeaf + x % kLeaf);
    if (leafCharges_[b] & bit) return;
    leafCharges_[b] |= bit;
    l.count[b] += 1.0f;
    l.cx[b] += float(x) + 0.5f;  // at most 64 half-integers below 2^13 per block: exact
    l.cy[b] += float(y) + 0.5f;
    l.cz[b] += float(z) + 0.5f;
  };
  if (obstacles) {
    const Grid grid{width, height, obstacles, depth};
    for (size_t i = 0; i < obstacles->size(); ++i)
      if ((*obstacles)[i]) {
        const Cell c = grid.cellAt(i);
        put(c.x + 1, c.y + 1, c.z + 1);
      }
  } else {  // the six faces of the domain
    for (int z = 0; z < dd_; ++z)
      for (int y = 0; y < dh_; ++y) {
        const bool face = z == 0 || z == dd_ - 1 || y == 0 || y == dh_ - 1;
        if (face)
          for (int x = 0; x < dw_; ++x) put(x, y, z);
        else
          put(0, y, z), put(dw_ - 1, y, z);
      }
  }
  for (size_t b = 0; b < n; ++b)
    if (l.count[b] > 0) l.cx[b] /= l.count[b], l.cy[b] /= l.count[b], l.cz[b] /= l.count[b];
  levels_.push_back(std::move(l));
  while (levels_.back().w > 1 || levels_.back().h > 1 || levels_.back().d > 1) {
    const Level& f = levels_.back();
    Level c{(f.w + 1) / 2, (f.h + 1) / 2, (f.d + 1) / 2, {}, {}, {}, {}};
    const size_t m = size_t(c.w) * size_t(c.h) * size_t(c.d);
    for (auto* v : {&c.count, &c.cx, &c.cy, &c.cz}) v->assign(m, 0.0f);
    for (int z = 0; z < f.d; ++z)
      for (int y = 0; y < f.h; ++y)
        for (int x = 0; x < f.w; ++x) {
          const size_t i = (size_t(z) * size_t(f.h) + size_t(y)) * size_t(f.w) + size_t(x);
          if (f.count[i] == 0) continue;
          const size_t b = (size_t(z / 2) * size_t(c.h) + size_t(y / 2)) * size_t(c.w) + size_t(x / 2);
          c.count[b] += f.count[i];
          c.cx[b] += f.cx[i] * f.count[i];
          c.cy[b] += f.cy[i] * f.count[i];
          c.cz[b] += f.cz[i] * f.count[i];
        }
    for (size_t b = 0; b < m; ++b)
      if (c.count[b] > 0) c.cx[b] /= c.count[b], c.cy[b] /= c.count[b], c.cz[b] /= c.count[b];
    levels_.push_back(std::move(c));
  }
}

// Sum of 1/r from the charges of block (bx, by, bz) of `level` to the point (domain coordinates).
double VolumeBoundary::visit(int level, int bx, int by, int bz, double px, double py, double pz) const {
  const Level& l = levels_[size_t(level)];
  if (bx >= l.w || by >= l.h || bz >= l.d) return 0.0;
  const size_t i = (size_t(bz) * size_t(l.h) + size_t(by)) * size_t(l.w) + size_t(bx);
  const double count = l.count[i];
  if (count == 0) return 0.0;
  const double side = double(kLeaf << level);
  const double r = std::sqrt((l.cx[i] - px) * (l.cx[i] - px) + (l.cy[i] - py) * (l.cy[i] - py) +
                             (l.cz[i] - pz) * (l.cz[i] - pz));
  if (side < kTheta * r) return count / r;
  if (level == 0) {  // voxel by voxel, in z, y, x order
    double sum = 0;
    const int x0 = bx * kLeaf, y0 = by * kLeaf, z0 = bz * kLeaf;
    for (uint64_t bits = leafCharges_[i]; bits; bits &= bits - 1) {
      const int k = __builtin_ctzll(bits);
      const double dx = x0 + k % kLeaf + 0.5 - px, dy = y0 + k / kLeaf % kLeaf + 0.5 - py,
                   dz = z0 + k / (kLeaf * kLeaf) + 0.5 - pz;
      sum += 1.0 / std::sqrt(dx * dx + dy * dy + dz * dz);
    }
    return sum;
  }
  double sum = 0;
  for (int c = 0; c < 8; ++c)
    sum += visit(level - 1, 2 * bx + (c & 1), 2 * by + ((c >> 1) & 1), 2 * bz + (c >> 2), px, py, pz);
  return sum;
}

double VolumeBoundary::potential(Cell c) const {
  const int x = c.x, y = c.y, z = c.z;
  const size_t m = (size_t(z) * size_t(h_) + size_t(y)) * size_t(w_) + size_t(x);
  if (memoVoxels_)
    if (float v = memo_.get(m); v != 0.0f) return v;
  // Grid voxel (x, y, z) is domain voxel (x + 1, y + 1, z + 1); its centre is + 0.5.
  const double v = visit(int(levels_.size()) - 1, 0, 0, 0, x + 1.5, y + 1.5, z + 1.5);
  if (memoVoxels_) {
    memo_.put(m, float(v));
    return float(v);  // the same value whether it came from the memo or not
  }
  return v;
}

size_t VolumeBoundary::bytes() const {
  size_t b = leafCharges_.size() * sizeof(uint64_t);
  for (const Level& l : levels_) b += l.count.size() * 4 * sizeof(float);
  return b + memo_.bytes();
}

}  // namespace detail

double boundaryPotential(int width, int height, int depth, const std::vector<uint8_t>& obstacles, Cell c) {
  return detail::cachedBoundary(width, height, depth, obstacles).potential(c);
}

}  // namespace effects::lightning
