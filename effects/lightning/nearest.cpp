// The k-d tree of nearest.h: built by median splits on the axis of the largest extent, searched
// depth first, nearer half first, pruning halves farther than the best distance so far.
#include "nearest.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace effects::lightning::detail {

namespace {
int coord(Cell c, int axis) { return axis == 0 ? c.x : axis == 1 ? c.y : c.z; }
int64_t squared(Cell a, Cell b) {
  const int64_t dx = a.x - b.x, dy = a.y - b.y, dz = a.z - b.z;
  return dx * dx + dy * dy + dz * dz;
}
}  // namespace

NearestCells::NearestCells(int width, int height, int depth, const std::vector<uint8_t>& flags) {
  const int d = std::max(depth, 1);
  auto in = [&](int x, int y, int z) {
    return flags[(size_t(z) * size_t(height) + size_t(y)) * size_t(width) + size_t(x)] != 0;
  };
  static constexpr int kFace[6][3] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  auto surface = [&](int x, int y, int z) {
    if (!in(x, y, z)) return false;
    for (const auto& f : kFace) {
      const int nx = x + f[0], ny = y + f[1], nz = z + f[2];
      if (nx >= 0 && ny >= 0 && nz >= 0 && nx < width && ny < height && nz < d && !in(nx, ny, nz)) return true;
    }
    return false;
  };
  size_t count = 0;  // counted first: the tree takes exactly its 13 bytes a cell
  for (int z = 0; z < d; ++z)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x) count += surface(x, y, z);
  cells_.reserve(count);
  for (int z = 0; z < d; ++z)
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (surface(x, y, z)) cells_.push_back({x, y, z});
  axis_.assign(cells_.size(), 0);
  build(0, cells_.size());
}

void NearestCells::build(size_t lo, size_t hi) {
  if (hi - lo < 2) return;
  int mn[3] = {cells_[lo].x, cells_[lo].y, cells_[lo].z}, mx[3] = {mn[0], mn[1], mn[2]};
  for (size_t i = lo; i < hi; ++i)
    for (int a = 0; a < 3; ++a) {
      mn[a] = std::min(mn[a], coord(cells_[i], a));
      mx[a] = std::max(mx[a], coord(cells_[i], a));
    }
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (mx[a] - mn[a] > mx[axis] - mn[axis]) axis = a;
  const size_t mid = lo + (hi - lo) / 2;
  std::nth_element(cells_.begin() + long(lo), cells_.begin() + long(mid), cells_.begin() + long(hi),
                   [axis](Cell a, Cell b) { return coord(a, axis) < coord(b, axis); });
  axis_[mid] = uint8_t(axis);
  build(lo, mid);
  build(mid + 1, hi);
}

void NearestCells::search(size_t lo, size_t hi, Cell c, int64_t& best) const {
  if (lo >= hi) return;
  const size_t mid = lo + (hi - lo) / 2;
  best = std::min(best, squared(c, cells_[mid]));
  if (hi - lo == 1) return;
  const int axis = axis_[mid];
  const int64_t gap = coord(c, axis) - coord(cells_[mid], axis);
  // Cells before mid have coordinates <= the middle's on the axis, cells after >= it.
  if (gap < 0) {
    search(lo, mid, c, best);
    if (gap * gap < best) search(mid + 1, hi, c, best);
  } else {
    search(mid + 1, hi, c, best);
    if (gap * gap < best) search(lo, mid, c, best);
  }
}

double NearestCells::distance(Cell c) const {
  int64_t best = std::numeric_limits<int64_t>::max();
  search(0, cells_.size(), c, best);
  return cells_.empty() ? INFINITY : std::sqrt(double(best));
}

}  // namespace effects::lightning::detail
