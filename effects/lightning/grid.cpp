#include "grid.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <functional>
#include <list>
#include <mutex>
#include <queue>

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

std::vector<uint64_t> obstacleBits(const std::vector<uint8_t>& obstacles) {
  std::vector<uint64_t> bits((obstacles.size() + 63) / 64, 0);
  uint64_t any = 0;
  for (size_t i = 0; i < obstacles.size(); i += 8) {
    uint64_t v = 0;
    std::memcpy(&v, obstacles.data() + i, std::min<size_t>(8, obstacles.size() - i));
    // 0x80 in each non-zero byte, then byte k's to bit k (the products do not overlap).
    const uint64_t nonzero = (((v & 0x7f7f7f7f7f7f7f7full) + 0x7f7f7f7f7f7f7f7full) | v) & 0x8080808080808080ull;
    const uint64_t byte = ((nonzero >> 7) * 0x0102040810204080ull) >> 56;
    bits[i / 64] |= byte << (i % 64);
    any |= byte;
  }
  if (!any) bits.clear();
  return bits;
}

std::shared_ptr<const void> cachedMap(int width, int height, int depth, const std::vector<uint64_t>& obstacleKey,
                                      bool* hit, const std::function<std::shared_ptr<const void>()>& build,
                                      size_t (*mapBytes)(const void*)) {
  // Least recently used first out, bounded in bytes (maps and their keys); 2-D and 3-D maps
  // share the budget.
  struct Entry {
    int w, h, d;
    std::vector<uint64_t> key;
    std::shared_ptr<const void> map;
    size_t mapBytes;
    size_t bytes() const { return key.size() * sizeof(uint64_t) + mapBytes; }
  };
  static std::mutex mu;
  static std::list<Entry> lru;  // most recent first
  constexpr size_t kBudgetBytes = size_t(64) << 20;
  {
    std::lock_guard<std::mutex> lock(mu);
    for (auto it = lru.begin(); it != lru.end(); ++it) {
      if (it->w == width && it->h == height && it->d == depth && it->key == obstacleKey) {
        lru.splice(lru.begin(), lru, it);
        if (hit) *hit = true;
        return lru.front().map;
      }
    }
  }
  if (hit) *hit = false;
  std::shared_ptr<const void> map = build();  // built outside the lock
  Entry entry{width, height, depth, obstacleKey, map, mapBytes(map.get())};
  if (entry.bytes() > kBudgetBytes) return map;  // used by this request only
  std::lock_guard<std::mutex> lock(mu);
  lru.push_front(std::move(entry));
  size_t total = 0;
  for (auto it = lru.begin(); it != lru.end();) {
    total += it->bytes();
    if (total > kBudgetBytes)
      it = lru.erase(it);
    else
      ++it;
  }
  return map;
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

bool lineOfSight(const Grid& g, Cell a, Cell b) {
  if (g.depth > 1) {
    // 3-D: the voxels the segment between the centres passes through (Amanatides & Woo);
    // every one must be free.
    int x = a.x, y = a.y, z = a.z;
    const int d[3] = {b.x - a.x, b.y - a.y, b.z - a.z};
    int step[3];
    double tMax[3], tDelta[3];
    for (int k = 0; k < 3; ++k) {
      step[k] = d[k] > 0 ? 1 : -1;
      tDelta[k] = d[k] ? 1.0 / std::abs(d[k]) : INFINITY;
      tMax[k] = d[k] ? 0.5 * tDelta[k] : INFINITY;
    }
    while (true) {
      if (g.blocked(x, y, z)) return false;
      if (x == b.x && y == b.y && z == b.z) return true;
      const int k = tMax[0] <= tMax[1] && tMax[0] <= tMax[2] ? 0 : tMax[1] <= tMax[2] ? 1 : 2;
      if (tMax[k] > 1.0) return true;  // rounding: the end voxel is reached
      (k == 0 ? x : k == 1 ? y : z) += step[k];
      tMax[k] += tDelta[k];
    }
  }
  // Bresenham; every cell on the line must be free.
  int dx = std::abs(b.x - a.x), dy = -std::abs(b.y - a.y);
  int sx = a.x < b.x ? 1 : -1, sy = a.y < b.y ? 1 : -1, err = dx + dy;
  int x = a.x, y = a.y;
  while (true) {
    if (g.blocked(x, y)) return false;
    if (x == b.x && y == b.y) return true;
    int e2 = 2 * err;
    if (e2 >= dy) {
      err += dy;
      x += sx;
    }
    if (e2 <= dx) {
      err += dx;
      y += sy;
    }
  }
}

std::vector<Cell> turningPoints(const std::vector<Cell>& path) {
  std::vector<Cell> out;
  for (size_t i = 1; i + 1 < path.size(); ++i) {
    int dx0 = path[i].x - path[i - 1].x, dy0 = path[i].y - path[i - 1].y, dz0 = path[i].z - path[i - 1].z;
    int dx1 = path[i + 1].x - path[i].x, dy1 = path[i + 1].y - path[i].y, dz1 = path[i + 1].z - path[i].z;
    if (dx0 != dx1 || dy0 != dy1 || dz0 != dz1) out.push_back(path[i]);
  }
  if (!path.empty()) out.push_back(path.back());
  return out;
}

}  // namespace detail

namespace {

// A* from `from` to the first goal cell it settles, with the octile (Manhattan) distance to the
// goals' bounding box [lo, hi] as the heuristic: admissible, and exact for a single goal.
template <class IsGoal>
std::vector<Cell> astarTo(int width, int height, const std::vector<uint8_t>& obstacles, Cell from, Cell lo, Cell hi,
                          IsGoal isGoal, int neighbourhood, int depth) {
  detail::Grid g{width, height, &obstacles, std::max(depth, 1)};
  const detail::Stencil st = detail::stencil(neighbourhood);
  const size_t n = g.cells();
  struct Visit {
    float cost;
    int32_t parent;  // + 1; 0: not seen yet
  };
  detail::CellMap<Visit> visits(n);  // a search on a large grid touches the cells around its path only
  const bool manhattan = st.size == 4 || st.size == 6;
  auto gap = [](int v, int a, int b) { return double(v < a ? a - v : v > b ? v - b : 0); };
  auto h = [&](Cell c) {
    double dx = gap(c.x, lo.x, hi.x), dy = gap(c.y, lo.y, hi.y), dz = gap(c.z, lo.z, hi.z);
    if (manhattan) return dx + dy + dz;
    if (depth == 0) return std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy);  // octile
    // 3-D octile: the largest difference straight, the middle one diagonally, the smallest
    // along space diagonals.
    double v[3] = {dx, dy, dz};
    std::sort(v, v + 3);
    return v[2] + (std::sqrt(2.0) - 1.0) * v[1] + (std::sqrt(3.0) - std::sqrt(2.0)) * v[0];
  };
  const float kStep[4] = {0.0f, 1.0f, float(std::sqrt(2.0)), float(std::sqrt(3.0))};
  using Item = std::pair<double, int32_t>;  // f, index (ties: smaller index first: deterministic)
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  const size_t s = g.index(from);
  size_t t = n;  // the goal reached
  visits.at(s) = {0.0f, int32_t(s) + 1};  // the start is its own parent: the walk back stops there
  open.push({h(from), int32_t(s)});
  while (!open.empty()) {
    auto [f, i] = open.top();
    open.pop();
    const Cell c = g.cellAt(size_t(i));
    const float ci = visits.get(size_t(i)).cost;
    if (f > ci + h(c) + 1e-6) continue;  // stale entry
    if (isGoal(size_t(i))) {
      t = size_t(i);
      break;
    }
    for (int k = 0; k < st.size; ++k) {
      const Cell m{c.x + st.dx[k], c.y + st.dy[k], c.z + st.dz[k]};
      if (!g.inside(m.x, m.y, m.z) || g.blocked(m.x, m.y, m.z)) continue;
      size_t j = g.index(m);
      float step = kStep[(st.dx[k] != 0) + (st.dy[k] != 0) + (st.dz[k] != 0)];
      float cj = ci + step;
      if (Visit& v = visits.at(j); v.parent == 0 || cj < v.cost) {
        v = {cj, i + 1};
        open.push({cj + h(m), int32_t(j)});
      }
    }
  }
  if (t == n) return {};
  std::vector<Cell> path;
  for (size_t i = t;; i = size_t(visits.get(i).parent - 1)) {
    path.push_back(g.cellAt(i));
    if (i == s) break;
  }
  std::reverse(path.begin(), path.end());
  return path;
}

}  // namespace

std::vector<Cell> astar(int width, int height, const std::vector<uint8_t>& obstacles, Cell from, Cell to,
                        int neighbourhood, int depth) {
  const size_t t = detail::Grid{width, height, &obstacles, std::max(depth, 1)}.index(to);
  return astarTo(width, height, obstacles, from, to, to, [t](size_t i) { return i == t; }, neighbourhood, depth);
}

std::vector<Cell> astarToRegion(int width, int height, const std::vector<uint8_t>& obstacles, Cell from,
                                const std::vector<uint8_t>& goals, int neighbourhood, int depth) {
  detail::Grid g{width, height, &obstacles, std::max(depth, 1)};
  Cell lo{width, height, g.depth}, hi{-1, -1, -1};
  for (size_t i = 0; i < goals.size() && i < g.cells(); ++i)
    if (goals[i]) {
      const Cell c = g.cellAt(i);
      lo = {std::min(lo.x, c.x), std::min(lo.y, c.y), std::min(lo.z, c.z)};
      hi = {std::max(hi.x, c.x), std::max(hi.y, c.y), std::max(hi.z, c.z)};
    }
  if (hi.x < 0 || goals.size() != g.cells()) return {};
  return astarTo(width, height, obstacles, from, lo, hi, [&](size_t i) { return goals[i] != 0; }, neighbourhood, depth);
}

double boundaryPotential(int width, int height, const std::vector<uint8_t>& obstacles, Cell c) {
  return detail::cachedBoundary(width, height, obstacles).potential(c);
}

}  // namespace effects::lightning
