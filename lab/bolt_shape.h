// A bolt's shape as distributions, for comparing the fast method with DBM by measures the
// calibration was not tuned to (issue 49; lab/lightning_shape.cpp). Independent of
// effects/lightning/shape.cpp's estimators: the box counts here are grid-aligned (no minimum
// over offsets) and every curve is kept, not just its slope.
//
//   boxCounts      N(s): boxes (3-D: cubes) of side s = 1, 2, 4, ... up to a quarter of the
//                  grid's smallest side that hold a bolt cell
//   massRadius     M(r): bolt cells within Euclidean distance r of the start, r = 2, 4, 8, ...
//   segments       cells between branch points, tips and the start along the tree (a segment
//                  ends at a node with no child or more than one)
//   angles         at each branch point, the angle (degrees) between its first two children's
//                  directions, each taken over up to kAngleReach cells along its segment
//   struckOffset   where the main channel ends, from below the start (x and z)
//   tips           two ways: tree leaves (cells nothing grew from), and cells with exactly one
//                  occupied 8-neighbour (3-D: 26-neighbour; what the eye counts as an end)
// Two samples are compared by Welch's z per curve point (largest |z|) and, for pooled
// distributions, by the Kolmogorov-Smirnov distance.
#pragma once

#include <algorithm>
#include <array>
#include <cmath>
#include <map>
#include <set>
#include <tuple>
#include <utility>
#include <vector>

#include <effects/lightning.h>

namespace bench::shape {

namespace lt = effects::lightning;

constexpr int kAngleReach = 4;

struct Measures {
  std::vector<double> boxCounts;   // N(s) for s = 1, 2, 4 ...
  std::vector<double> massRadius;  // M(r) for r = 2, 4, 8 ...
  std::vector<double> segments;    // lengths, cells
  std::vector<double> angles;      // degrees
  double leafTips = 0, neighbourTips = 0, cells = 0;
  double struckOffset = 0;         // the main channel's end from below the start (x, z)
};

// depth 0: a 2-D grid.
inline Measures measure(const lt::Bolt& bolt, int width, int height, int depth = 0) {
  Measures m;
  const auto& nodes = bolt.nodes;
  m.cells = double(nodes.size());
  using Key = std::tuple<int, int, int>;
  std::set<Key> occupied;
  for (const auto& n : nodes) occupied.insert({n.cell.x, n.cell.y, n.cell.z});
  const int smallest = depth ? std::min({width, height, depth}) : std::min(width, height);
  for (int s = 1; s <= smallest / 4; s *= 2) {
    std::set<Key> boxes;
    for (const auto& [x, y, z] : occupied) boxes.insert({x / s, y / s, z / s});
    m.boxCounts.push_back(double(boxes.size()));
  }
  if (!nodes.empty()) {
    const lt::Cell o = nodes.front().cell;
    for (int r = 2; r <= std::max({width, height, depth}); r *= 2) {
      double count = 0;
      for (const auto& n : nodes)
        count += std::hypot(double(n.cell.x - o.x), double(n.cell.y - o.y), double(n.cell.z - o.z)) <= double(r);
      m.massRadius.push_back(count);
    }
  }
  if (!bolt.mainChannel.empty()) {
    const lt::Cell a = nodes.front().cell, b = nodes[size_t(bolt.mainChannel.back())].cell;
    m.struckOffset = std::hypot(double(b.x - a.x), double(b.z - a.z));
  }
  std::vector<std::vector<int>> children(nodes.size());
  for (size_t i = 0; i < nodes.size(); ++i)
    if (nodes[i].parent >= 0) children[size_t(nodes[i].parent)].push_back(int(i));
  const int reachZ = depth ? 1 : 0;
  for (size_t i = 0; i < nodes.size(); ++i) {
    m.leafTips += children[i].empty() && i != 0;
    int neighbours = 0;
    for (int dz = -reachZ; dz <= reachZ; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
          if ((dx || dy || dz) && occupied.count({nodes[i].cell.x + dx, nodes[i].cell.y + dy, nodes[i].cell.z + dz})) ++neighbours;
    m.neighbourTips += neighbours == 1;
  }
  // Segments: from the start and from every branch point, each child's run until a node that
  // does not have exactly one child.
  auto walk = [&](int from) {  // returns (length, end node), following single children
    int length = 1, at = from;
    while (children[size_t(at)].size() == 1) {
      at = children[size_t(at)].front();
      ++length;
    }
    return std::make_pair(length, at);
  };
  auto direction = [&](int from, int first) {  // over up to kAngleReach cells from `from`
    int at = first;
    for (int k = 1; k < kAngleReach && children[size_t(at)].size() == 1; ++k) at = children[size_t(at)].front();
    const lt::Cell a = nodes[size_t(from)].cell, b = nodes[size_t(at)].cell;
    return std::array<double, 3>{double(b.x - a.x), double(b.y - a.y), double(b.z - a.z)};
  };
  std::vector<int> starts = {0};
  while (!starts.empty() && !nodes.empty()) {
    const int from = starts.back();
    starts.pop_back();
    const auto& kids = children[size_t(from)];
    if (kids.size() >= 2) {  // the angle between the first two children's directions, 0 to 180
      const auto u = direction(from, kids[0]), v = direction(from, kids[1]);
      const double dot = u[0] * v[0] + u[1] * v[1] + u[2] * v[2];
      const double len = std::sqrt((u[0] * u[0] + u[1] * u[1] + u[2] * u[2]) * (v[0] * v[0] + v[1] * v[1] + v[2] * v[2]));
      m.angles.push_back(std::acos(std::clamp(dot / len, -1.0, 1.0)) * 180.0 / M_PI);
    }
    for (int k : kids) {
      const auto [length, end] = walk(k);
      m.segments.push_back(double(length));
      if (children[size_t(end)].size() >= 2) starts.push_back(end);
    }
  }
  return m;
}

// Box-counting slope of N(s) over its scales (least squares of log N against log 1/s).
inline double slope(const std::vector<double>& counts) {
  double sx = 0, sy = 0, sxx = 0, sxy = 0;
  const double n = double(counts.size());
  for (size_t i = 0; i < counts.size(); ++i) {
    const double x = -std::log(double(1 << i)), y = std::log(std::max(counts[i], 1.0));
    sx += x, sy += y, sxx += x * x, sxy += x * y;
  }
  return (n * sxy - sx * sy) / (n * sxx - sx * sx);
}

// Largest Welch |z| over the points of two sets of curves (each a sample over seeds).
inline double curveZ(const std::vector<std::vector<double>>& a, const std::vector<std::vector<double>>& b) {
  double worst = 0;
  const size_t points = std::min(a.empty() ? 0 : a[0].size(), b.empty() ? 0 : b[0].size());
  for (size_t p = 0; p < points; ++p) {
    auto stats = [&](const std::vector<std::vector<double>>& s) {
      double mean = 0, var = 0;
      for (const auto& c : s) mean += c[p];
      mean /= double(s.size());
      for (const auto& c : s) var += (c[p] - mean) * (c[p] - mean);
      return std::make_pair(mean, s.size() > 1 ? var / double(s.size() - 1) : 0.0);
    };
    const auto [ma, va] = stats(a);
    const auto [mb, vb] = stats(b);
    const double se = std::sqrt(va / double(a.size()) + vb / double(b.size()));
    if (se > 0) worst = std::max(worst, std::fabs(ma - mb) / se);
  }
  return worst;
}

// Kolmogorov-Smirnov distance between two pooled samples.
inline double ks(std::vector<double> a, std::vector<double> b) {
  if (a.empty() || b.empty()) return 1.0;
  std::sort(a.begin(), a.end());
  std::sort(b.begin(), b.end());
  double worst = 0;
  size_t i = 0, j = 0;
  while (i < a.size() && j < b.size()) {
    const double v = std::min(a[i], b[j]);
    while (i < a.size() && a[i] <= v) ++i;
    while (j < b.size() && b[j] <= v) ++j;
    worst = std::max(worst, std::fabs(double(i) / double(a.size()) - double(j) / double(b.size())));
  }
  return worst;
}

}  // namespace bench::shape
