// Bolt tree -> polylines for renderers; box-counting fractal dimension.
#include <algorithm>
#include <cmath>

#include "effects/lightning.h"

namespace effects::lightning {
namespace {

// A hash of (seed, node) -> two uniforms: jitter independent of growth order and RNG state.
void jitterOf(uint64_t seed, int node, double& u, double& v, double* w) {
  Rng r(seed ^ (0x9E3779B97F4A7C15ULL * uint64_t(node + 1)), 0xB5297A4D3F84D5B5ULL);
  u = r.uniform();
  v = r.uniform();
  if (w) *w = r.uniform();  // 3-D bolts only: 2-D draws stay as they were
}

// The bolt as a tree: each node's children, the height of its subtree, and its tree distance
// from the main channel.
struct Tree {
  std::vector<std::vector<int>> children;
  std::vector<int> depth, fromMain;
};

Tree treeOf(const Bolt& bolt) {
  const size_t n = bolt.nodes.size();
  Tree t;
  t.children.resize(n);
  for (size_t i = 1; i < n; ++i) t.children[size_t(bolt.nodes[i].parent)].push_back(int(i));
  // Height of each subtree (nodes are in growth order: children come after parents).
  t.depth.assign(n, 0);
  for (size_t i = n; i-- > 1;) {
    int p = bolt.nodes[i].parent;
    t.depth[size_t(p)] = std::max(t.depth[size_t(p)], t.depth[i] + 1);
  }
  // Tree distance from the main channel.
  t.fromMain.assign(n, -1);
  for (int m : bolt.mainChannel) t.fromMain[size_t(m)] = 0;
  for (size_t i = 1; i < n; ++i)
    if (t.fromMain[i] < 0) t.fromMain[i] = t.fromMain[size_t(bolt.nodes[i].parent)] + 1;
  return t;
}

// The child with the deepest subtree (ties: the earliest), which continues its parent's
// line; -1 for a leaf.
int deepestChild(const Tree& t, size_t node) {
  int best = -1;
  for (int d : t.children[node])
    if (best < 0 || t.depth[size_t(d)] > t.depth[size_t(best)]) best = d;
  return best;
}

// A node's polyline vertex: its cell's centre, jittered, and the intensity of its branch.
Vertex vertexOf(const Bolt& bolt, const ShapeParams& s, const Tree& t, int node) {
  const Node& nd = bolt.nodes[size_t(node)];
  double u = 0.5, v = 0.5, w = 0.5;
  if (s.jitter > 0) jitterOf(s.jitterSeed, node, u, v, bolt.depth ? &w : nullptr);
  Vertex out;
  out.x = float(nd.cell.x + 0.5 + s.jitter * (u - 0.5));
  out.y = float(nd.cell.y + 0.5 + s.jitter * (v - 0.5));
  if (bolt.depth) out.z = float(nd.cell.z + 0.5 + s.jitter * (w - 0.5));
  out.step = nd.step;
  out.node = node;
  out.intensity = t.fromMain[size_t(node)] == 0
                      ? 1.0f
                      : float(s.branchIntensity * std::exp(-(t.fromMain[size_t(node)] - 1) / s.branchFalloff));
  return out;
}

}  // namespace

std::vector<Polyline> polylines(const Bolt& bolt, const ShapeParams& s) {
  const size_t n = bolt.nodes.size();
  const Tree tree = treeOf(bolt);
  auto vertex = [&](int node) { return vertexOf(bolt, s, tree, node); };

  std::vector<Polyline> out;
  std::vector<uint8_t> onMain(n, 0);
  Polyline main;
  main.main = true;
  main.width = float(2 * s.branchWidth);
  for (int m : bolt.mainChannel) {
    onMain[size_t(m)] = 1;
    main.vertices.push_back(vertex(m));
  }
  out.push_back(std::move(main));
  // Branches: every child that is not the continuation of its parent's line starts one.
  // The continuation of a branch is its child with the deepest subtree (ties: earliest).
  for (size_t i = 0; i < n; ++i) {
    for (int c : tree.children[i]) {
      if (onMain[size_t(c)]) continue;
      if (!onMain[i] && deepestChild(tree, i) == c) continue;
      Polyline b;
      b.width = float(s.branchWidth);
      b.vertices.push_back(vertex(int(i)));
      for (int cur = c; cur >= 0; cur = deepestChild(tree, size_t(cur))) b.vertices.push_back(vertex(cur));
      out.push_back(std::move(b));
    }
  }
  return out;
}

namespace {

// D from box counts: the slope of log N against log(1/s) over the straightest run of >= 4
// scales (the whole range when there are fewer).
double slopeOfCounts(const std::vector<double>& logInvS, const std::vector<double>& logN) {
  auto fit = [&](size_t a, size_t b, double& slope) {  // least squares over [a, b)
    double n = double(b - a), sx = 0, sy = 0, sxx = 0, sxy = 0, syy = 0;
    for (size_t i = a; i < b; ++i) {
      sx += logInvS[i];
      sy += logN[i];
      sxx += logInvS[i] * logInvS[i];
      sxy += logInvS[i] * logN[i];
      syy += logN[i] * logN[i];
    }
    double vx = sxx - sx * sx / n, vy = syy - sy * sy / n, cxy = sxy - sx * sy / n;
    slope = vx > 0 ? cxy / vx : 0.0;
    return (vx > 0 && vy > 0) ? cxy * cxy / (vx * vy) : 0.0;  // R^2
  };
  size_t m = logN.size();
  if (m < 2) return 0.0;
  double bestSlope = 0;
  fit(0, m, bestSlope);
  if (m < 4) return bestSlope;
  // The straight part: the run of >= 4 consecutive scales with the best R^2 (longest on ties).
  double bestR2 = -1;
  size_t bestLen = 0;
  for (size_t a = 0; a + 4 <= m; ++a)
    for (size_t b = a + 4; b <= m; ++b) {
      double slope, r2 = fit(a, b, slope);
      if (r2 > bestR2 + 1e-4 || (r2 >= bestR2 - 1e-4 && b - a > bestLen)) {
        bestR2 = std::max(r2, bestR2);
        bestSlope = slope;
        bestLen = b - a;
      }
    }
  return bestSlope;
}

// Box counts for sides 1, 2, 4, ... up to maxBox: per side the fewest boxes over the offsets
// 0 and s/2 on each axis; key(c, s, ox, oy, oz) names the box of cell c.
template <class Key>
double boxCountingDimension(const std::vector<Cell>& cells, int maxBox, int offsets, Key key) {
  std::vector<double> logInvS, logN;
  std::vector<uint64_t> keys;
  for (int s = 1; s <= maxBox; s *= 2) {
    size_t best = SIZE_MAX;
    for (int off = 0; off < offsets; ++off) {
      int ox = (off & 1) ? s / 2 : 0, oy = (off & 2) ? s / 2 : 0, oz = (off & 4) ? s / 2 : 0;
      if (s == 1 && off) break;
      keys.clear();
      for (const Cell& c : cells) keys.push_back(key(c, s, ox, oy, oz));
      std::sort(keys.begin(), keys.end());
      best = std::min(best, size_t(std::unique(keys.begin(), keys.end()) - keys.begin()));
    }
    logInvS.push_back(-std::log(double(s)));
    logN.push_back(std::log(double(best)));
  }
  return slopeOfCounts(logInvS, logN);
}

}  // namespace

double fractalDimension(const std::vector<Cell>& cells, int width, int height) {
  if (cells.size() < 2) return 0.0;
  return boxCountingDimension(cells, std::max(1, std::min(width, height) / 4), 4, [](Cell c, int s, int ox, int oy, int) {
    return uint64_t(uint32_t((c.x + ox) / s)) << 32 | uint32_t((c.y + oy) / s);
  });
}

double fractalDimension(const std::vector<Cell>& cells, int width, int height, int depth) {
  if (cells.size() < 2) return 0.0;
  return boxCountingDimension(cells, std::max(1, std::min({width, height, depth}) / 4), 8,
                              [](Cell c, int s, int ox, int oy, int oz) {
                                return uint64_t(uint32_t((c.x + ox) / s)) << 42 |
                                       uint64_t(uint32_t((c.y + oy) / s)) << 21 | uint32_t((c.z + oz) / s);
                              });
}

BoltShape shapeOf(const Bolt& bolt, int width, int height, int depth) {
  std::vector<int> children(bolt.nodes.size(), 0);
  std::vector<Cell> cells;
  cells.reserve(bolt.nodes.size());
  for (const Node& n : bolt.nodes) {
    if (n.parent >= 0) ++children[size_t(n.parent)];
    cells.push_back(n.cell);
  }
  BoltShape out;
  out.cells = double(cells.size());
  out.tips = double(std::count(children.begin(), children.end(), 0));
  out.branchPoints = double(std::count_if(children.begin(), children.end(), [](int c) { return c >= 2; }));
  out.dimension = depth ? fractalDimension(cells, width, height, depth) : fractalDimension(cells, width, height);
  return out;
}

ShapeDistance shapeDistance(const std::vector<BoltShape>& method, const std::vector<BoltShape>& reference) {
  // Mean and the variance of the mean of one measure over a set.
  auto stats = [](const std::vector<BoltShape>& v, double BoltShape::*m, double& mean, double& varMean) {
    mean = 0;
    for (const BoltShape& b : v) mean += b.*m / double(v.size());
    double var = 0;
    for (const BoltShape& b : v) var += (b.*m - mean) * (b.*m - mean);
    varMean = v.size() > 1 ? var / double(v.size() - 1) / double(v.size()) : 0.0;
  };
  ShapeDistance d;
  if (method.empty() || reference.empty()) return d;
  for (auto [m, z] : {std::pair{&BoltShape::cells, &ShapeDistance::cells}, std::pair{&BoltShape::tips, &ShapeDistance::tips},
                      std::pair{&BoltShape::dimension, &ShapeDistance::dimension}}) {
    double ma, va, mr, vr;
    stats(method, m, ma, va);
    stats(reference, m, mr, vr);
    d.mean.*m = ma;
    d.refMean.*m = mr;
    const double diff = std::fabs(ma - mr), se = std::sqrt(va + vr);
    // No spread on either side (a forced bolt): equal is 0, different is a certain difference.
    d.*z = se > 0 ? diff / se : diff > 1e-12 * std::max(1.0, std::fabs(mr)) ? 1e9 : 0.0;
    d.worst = std::max(d.worst, d.*z);
  }
  return d;
}

}  // namespace effects::lightning
