#include "astar.h"

#include <algorithm>
#include <cmath>
#include <queue>

namespace effects::lightning {
namespace detail {

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

}  // namespace effects::lightning
