#include "boundary_map.h"
#include "hooks.h"

#include <algorithm>
#include <cmath>

#include "map_cache.h"

namespace effects::lightning {
namespace detail {

BoundaryMap::BoundaryMap(int width, int height, const std::vector<uint8_t>* obstacles)
    : dw_(width + 2),
      dh_(height + 2),
      qw_((dw_ + 1) / 2),
      qh_((dh_ + 1) / 2),
      memoCells_(size_t(width) * size_t(height) <= kMemoCells ? size_t(width) * size_t(height) : 0),
      memo_(memoCells_) {
  quads_.assign(size_t(qw_) * size_t(qh_), 0);
  auto put = [&](int dx, int dy) {
    quads_[size_t(dy / 2) * size_t(qw_) + size_t(dx / 2)] |= uint8_t(1u << ((dx & 1) + 2 * (dy & 1)));
  };
  if (obstacles) {
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if ((*obstacles)[size_t(y) * size_t(width) + size_t(x)]) put(x + 1, y + 1);
  } else {
    for (int dx = 0; dx < dw_; ++dx) put(dx, 0), put(dx, dh_ - 1);
    for (int dy = 1; dy + 1 < dh_; ++dy) put(0, dy), put(dw_ - 1, dy);
  }
  // 4x4 blocks straight from the cells, then 2x2 of the level below.
  Level l{(dw_ + 3) / 4, (dh_ + 3) / 4, {}, {}, {}};
  const size_t n = size_t(l.w) * size_t(l.h);
  l.count.assign(n, 0.0f);
  l.cx.assign(n, 0.0f);
  l.cy.assign(n, 0.0f);
  for (int dy = 0; dy < dh_; ++dy)
    for (int dx = 0; dx < dw_; ++dx)
      if (charge(dx, dy)) {
        size_t b = size_t(dy / 4) * size_t(l.w) + size_t(dx / 4);
        l.count[b] += 1.0f;
        l.cx[b] += float(dx) + 0.5f;  // sums of at most 16 half-integers < 2^24: exact
        l.cy[b] += float(dy) + 0.5f;
      }
  for (size_t b = 0; b < n; ++b)
    if (l.count[b] > 0) l.cx[b] /= l.count[b], l.cy[b] /= l.count[b];
  levels_.push_back(std::move(l));
  while (levels_.back().w > 1 || levels_.back().h > 1) {
    const Level& f = levels_.back();
    Level c{(f.w + 1) / 2, (f.h + 1) / 2, {}, {}, {}};
    size_t m = size_t(c.w) * size_t(c.h);
    c.count.assign(m, 0.0f);
    c.cx.assign(m, 0.0f);
    c.cy.assign(m, 0.0f);
    for (int y = 0; y < c.h; ++y)
      for (int x = 0; x < c.w; ++x) {
        double cnt = 0, sx = 0, sy = 0;
        for (int k = 0; k < 4; ++k) {
          int fx = 2 * x + k % 2, fy = 2 * y + k / 2;
          if (fx >= f.w || fy >= f.h) continue;
          size_t fi = size_t(fy) * size_t(f.w) + size_t(fx);
          cnt += f.count[fi];
          sx += double(f.count[fi]) * f.cx[fi];
          sy += double(f.count[fi]) * f.cy[fi];
        }
        size_t ci = size_t(y) * size_t(c.w) + size_t(x);
        c.count[ci] = float(cnt);
        if (cnt > 0) {
          c.cx[ci] = float(sx / cnt);
          c.cy[ci] = float(sy / cnt);
        }
      }
    levels_.push_back(std::move(c));
  }
}

size_t BoundaryMap::bytes() const {
  size_t b = quads_.size() + memo_.bytes();
  for (const Level& l : levels_) b += l.count.size() * 3 * sizeof(float);
  return b;
}

double BoundaryMap::visit(int level, int bx, int by, double px, double py) const {
  // Levels 0 and 1 (cells, 2x2 blocks) come from the charge masks; 2 and up are stored.
  static constexpr float kCount[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
  static constexpr float kSumX[16] = {0, 0, 1, 1, 0, 0, 1, 1, 1, 1, 2, 2, 1, 1, 2, 2};
  static constexpr float kSumY[16] = {0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 2, 2, 2, 2};
  float count = 0, cx = 0, cy = 0;
  if (level >= 2) {
    const Level& l = levels_[size_t(level - 2)];
    if (bx >= l.w || by >= l.h) return 0.0;
    size_t i = size_t(by) * size_t(l.w) + size_t(bx);
    count = l.count[i], cx = l.cx[i], cy = l.cy[i];
  } else if (level == 1) {
    if (bx >= qw_ || by >= qh_) return 0.0;
    const uint8_t m = quad(bx, by);
    count = kCount[m];
    if (count > 0) cx = float(2 * bx) + 0.5f + kSumX[m] / count, cy = float(2 * by) + 0.5f + kSumY[m] / count;
  } else {
    if (bx >= dw_ || by >= dh_ || !charge(bx, by)) return 0.0;
    count = 1, cx = float(bx) + 0.5f, cy = float(by) + 0.5f;
  }
  if (count == 0.0f) return 0.0;
  double dx = cx - px, dy = cy - py;
  double r2 = dx * dx + dy * dy;
  double blockSize = double(1 << level);
  // Opening criterion theta = 0.5: use the block as one charge when its size is at most half
  // the distance to its centroid.
  if (level == 0 || blockSize * blockSize * 4.0 <= r2) return r2 > 0 ? count / std::sqrt(r2) : 0.0;
  double sum = 0;
  for (int k = 0; k < 4; ++k) sum += visit(level - 1, 2 * bx + k % 2, 2 * by + k / 2, px, py);
  return sum;
}

double BoundaryMap::potential(Cell c) const {
  const int x = c.x, y = c.y;
  const size_t i = size_t(y) * size_t(dw_ - 2) + size_t(x);
  if (memoCells_)
    if (float v = memo_.get(i); v != 0.0f) return v;
  double px = x + 1.5, py = y + 1.5;  // domain coordinates of the cell centre
  const double v = visit(int(levels_.size()) + 1, 0, 0, px, py);
  if (memoCells_) {
    memo_.put(i, float(v));
    return float(v);  // the same value whether it came from the memo or not
  }
  return v;
}

namespace {
// The border's map (key: no obstacles) and, where any cell is blocked, the obstacles' map,
// of a 2-D (depth 0) or 3-D grid.
template <class Map, class Make>
SceneBoundary<Map> sceneBoundary(int width, int height, int depth, const std::vector<uint8_t>& obstacles,
                                 const Make& make) {
  SceneBoundary<Map> b;
  auto bytes = [](const void* m) { return static_cast<const Map*>(m)->bytes(); };
  auto get = [&](const std::vector<uint64_t>& key, const std::vector<uint8_t>* cells) {
    bool hit = false;
    auto map = std::static_pointer_cast<const Map>(
        cachedMap(width, height, depth, key, &hit, [&] { return make(cells); }, bytes));
    b.cached = b.cached && hit;
    return map;
  };
  b.border = get({}, nullptr);
  if (std::vector<uint64_t> key = obstacleBits(obstacles); !key.empty()) b.obstacles = get(key, &obstacles);
  return b;
}
}  // namespace

SceneBoundary<BoundaryMap> cachedBoundary(int width, int height, const std::vector<uint8_t>& obstacles) {
  return sceneBoundary<BoundaryMap>(width, height, 0, obstacles, [&](const std::vector<uint8_t>* cells) {
    return std::make_shared<const BoundaryMap>(width, height, cells);
  });
}

SceneBoundary<VolumeBoundary> cachedBoundary(int width, int height, int depth, const std::vector<uint8_t>& obstacles) {
  return sceneBoundary<VolumeBoundary>(width, height, depth, obstacles, [&](const std::vector<uint8_t>* cells) {
    return std::make_shared<const VolumeBoundary>(width, height, depth, cells);
  });
}

}  // namespace detail

double boundaryPotential(int width, int height, const std::vector<uint8_t>& obstacles, Cell c) {
  return detail::cachedBoundary(width, height, obstacles).potential(c);
}

}  // namespace effects::lightning
