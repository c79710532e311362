#include "grid.h"

#include <algorithm>
#include <cmath>
#include <list>
#include <mutex>
#include <queue>

namespace effects::lightning {
namespace detail {

BoundaryMap::BoundaryMap(int width, int height, const std::vector<uint8_t>& obstacles) {
  int domain = std::max(width, height) + 2;
  int size = 1;
  while (size < domain) size *= 2;
  Level base{size, std::vector<float>(size_t(size) * size), {}, {}};
  base.cx.assign(base.count.size(), 0.0f);
  base.cy.assign(base.count.size(), 0.0f);
  auto put = [&](int x, int y) {  // grid coordinates; the ring is at -1 and width/height
    size_t i = size_t(y + offset_) * size + size_t(x + offset_);
    base.count[i] = 1.0f;
    base.cx[i] = float(x + offset_) + 0.5f;
    base.cy[i] = float(y + offset_) + 0.5f;
  };
  for (int x = -1; x <= width; ++x) {
    put(x, -1);
    put(x, height);
  }
  for (int y = 0; y < height; ++y) {
    put(-1, y);
    put(width, y);
  }
  if (!obstacles.empty())
    for (int y = 0; y < height; ++y)
      for (int x = 0; x < width; ++x)
        if (obstacles[size_t(y) * width + x]) put(x, y);
  levels_.push_back(std::move(base));
  while (levels_.back().size > 1) {
    const Level& f = levels_.back();
    Level c{f.size / 2, {}, {}, {}};
    size_t n = size_t(c.size) * c.size;
    c.count.assign(n, 0.0f);
    c.cx.assign(n, 0.0f);
    c.cy.assign(n, 0.0f);
    for (int y = 0; y < c.size; ++y)
      for (int x = 0; x < c.size; ++x) {
        double cnt = 0, sx = 0, sy = 0;
        for (int k = 0; k < 4; ++k) {
          size_t fi = size_t(2 * y + k / 2) * f.size + size_t(2 * x + k % 2);
          cnt += f.count[fi];
          sx += double(f.count[fi]) * f.cx[fi];
          sy += double(f.count[fi]) * f.cy[fi];
        }
        size_t ci = size_t(y) * c.size + x;
        c.count[ci] = float(cnt);
        if (cnt > 0) {
          c.cx[ci] = float(sx / cnt);
          c.cy[ci] = float(sy / cnt);
        }
      }
    levels_.push_back(std::move(c));
  }
}

double BoundaryMap::visit(int level, int bx, int by, double px, double py) const {
  const Level& l = levels_[size_t(level)];
  size_t i = size_t(by) * l.size + size_t(bx);
  float count = l.count[i];
  if (count == 0.0f) return 0.0;
  double dx = l.cx[i] - px, dy = l.cy[i] - py;
  double r2 = dx * dx + dy * dy;
  double blockSize = double(1 << level);
  // Opening criterion theta = 0.5: use the block as one charge when its size is at most half
  // the distance to its centroid.
  if (level == 0 || blockSize * blockSize * 4.0 <= r2) return r2 > 0 ? count / std::sqrt(r2) : 0.0;
  double sum = 0;
  for (int k = 0; k < 4; ++k) sum += visit(level - 1, 2 * bx + k % 2, 2 * by + k / 2, px, py);
  return sum;
}

double BoundaryMap::potential(int x, int y) const {
  double px = x + offset_ + 0.5, py = y + offset_ + 0.5;
  return visit(int(levels_.size()) - 1, 0, 0, px, py);
}

std::shared_ptr<const BoundaryMap> cachedBoundaryMap(int width, int height, const std::vector<uint8_t>& obstacles,
                                                     bool* hit) {
  struct Entry {
    int w, h;
    std::vector<uint8_t> obstacles;
    std::shared_ptr<const BoundaryMap> map;
  };
  static std::mutex mu;
  static std::list<Entry> lru;  // most recent first
  constexpr size_t kCapacity = 8;
  {
    std::lock_guard<std::mutex> lock(mu);
    for (auto it = lru.begin(); it != lru.end(); ++it) {
      if (it->w == width && it->h == height && it->obstacles == obstacles) {
        lru.splice(lru.begin(), lru, it);
        if (hit) *hit = true;
        return lru.front().map;
      }
    }
  }
  if (hit) *hit = false;
  auto map = std::make_shared<const BoundaryMap>(width, height, obstacles);  // built outside the lock
  std::lock_guard<std::mutex> lock(mu);
  lru.push_front({width, height, obstacles, map});
  if (lru.size() > kCapacity) lru.pop_back();
  return map;
}

bool lineOfSight(const Grid& g, Cell a, Cell b) {
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
    int dx0 = path[i].x - path[i - 1].x, dy0 = path[i].y - path[i - 1].y;
    int dx1 = path[i + 1].x - path[i].x, dy1 = path[i + 1].y - path[i].y;
    if (dx0 != dx1 || dy0 != dy1) out.push_back(path[i]);
  }
  if (!path.empty()) out.push_back(path.back());
  return out;
}

}  // namespace detail

std::vector<Cell> astar(int width, int height, const std::vector<uint8_t>& obstacles, Cell from, Cell to) {
  detail::Grid g{width, height, &obstacles};
  const size_t n = size_t(width) * size_t(height);
  std::vector<float> cost(n, INFINITY);
  std::vector<int32_t> parent(n, -1);
  auto h = [&](int x, int y) {
    double dx = std::abs(x - to.x), dy = std::abs(y - to.y);
    return std::max(dx, dy) + (std::sqrt(2.0) - 1.0) * std::min(dx, dy);  // octile
  };
  using Item = std::pair<double, int32_t>;  // f, index (ties: smaller index first: deterministic)
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> open;
  size_t s = g.index(from), t = g.index(to);
  cost[s] = 0;
  open.push({h(from.x, from.y), int32_t(s)});
  while (!open.empty()) {
    auto [f, i] = open.top();
    open.pop();
    int x = i % width, y = i / width;
    if (f > cost[size_t(i)] + h(x, y) + 1e-6) continue;  // stale entry
    if (size_t(i) == t) break;
    for (int k = 0; k < 8; ++k) {
      int nx = x + detail::kDx[k], ny = y + detail::kDy[k];
      if (!g.inside(nx, ny) || g.blocked(nx, ny)) continue;
      size_t j = size_t(ny) * width + nx;
      float c = cost[size_t(i)] + ((detail::kDx[k] && detail::kDy[k]) ? float(std::sqrt(2.0)) : 1.0f);
      if (c < cost[j]) {
        cost[j] = c;
        parent[j] = i;
        open.push({c + h(nx, ny), int32_t(j)});
      }
    }
  }
  if (parent[t] < 0 && s != t) return {};
  std::vector<Cell> path;
  for (int32_t i = int32_t(t); i >= 0; i = parent[size_t(i)]) path.push_back({i % width, i / width});
  std::reverse(path.begin(), path.end());
  return path;
}

double boundaryPotential(int width, int height, const std::vector<uint8_t>& obstacles, Cell c) {
  return detail::BoundaryMap(width, height, obstacles).potential(c.x, c.y);
}

}  // namespace effects::lightning
