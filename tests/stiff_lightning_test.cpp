// Exact DBM on stiff geometries, checked by invariances and a high-precision reference, not by
// snapshots: channels whose field ahead of the bolt decays like exp(-pi L / (w + 1)) far below
// double's range (DeepField, docs/effects.md section 1.3), pockets behind obstacles, eta at its
// limits, 3-D tubes. The larger sizes run in the stability report (tests/stability/lightning.py).
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <vector>

#include <gtest/gtest.h>

#include <effects/lightning.h>

#include "lightning/deep_field.h"

namespace {

using namespace effects::lightning;

Params channel(int width, int length, double eta, uint64_t seed) {
  Params p;
  p.width = width;
  p.height = length;
  p.start = {width / 2, 0};
  p.targets = {{width / 2, length - 1}};
  p.method = Method::kDbm;
  p.eta = eta;
  p.seed = seed;
  return p;
}

// Mean cells per row of channel over seeds 1..n.
double cellsPerRow(Params p, int seeds) {
  double sum = 0;
  for (int s = 1; s <= seeds; ++s) {
    p.seed = uint64_t(s);
    auto r = grow(p);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
    if (!r.ok()) return 0;
    sum += double(r.value().nodes.size()) / p.height;
  }
  return sum / seeds;
}

// Growth at the tip does not depend on how far the target is: cells per row of channel are the
// same at length 64 and 16 times longer (before DeepField, 3 wide: 1.05 at 64, 2.9 at 512 and
// 98 % of the channel filled at 2048).
TEST(StiffLightning, ChannelGrowthDoesNotDependOnItsLength) {
  for (int width : {3, 5, 7}) {
    const double shortRun = cellsPerRow(channel(width, 64, 2, 1), 6);
    const double longRun = cellsPerRow(channel(width, 1024, 2, 1), 2);
    printf("width %d: cells per row %.3f at length 64, %.3f at 1024\n", width, shortRun, longRun);
    EXPECT_NEAR(longRun / shortRun, 1.0, 0.12) << "width " << width;
    EXPECT_LT(longRun, 0.5 * width) << "the bolt fills its channel: width " << width;
  }
}

// The same in 3-D: a 3 x 3 tube.
TEST(StiffLightning, TubeGrowthDoesNotDependOnItsLength) {
  auto tube = [](int length) {
    Params p;
    p.width = 3;
    p.height = 3;
    p.depth = length;
    p.start = {1, 1, 0};
    p.targets = {{1, 1, length - 1}};
    p.method = Method::kDbm;
    p.neighbourhood = 6;
    return p;
  };
  const double shortRun = cellsPerRow(tube(48), 6) * 3 / 48;  // cellsPerRow divides by height 3
  const double longRun = cellsPerRow(tube(480), 2) * 3 / 480;
  printf("3 x 3 tube: cells per voxel of length %.3f at 48, %.3f at 480\n", shortRun, longRun);
  EXPECT_NEAR(longRun / shortRun, 1.0, 0.12);
  EXPECT_LT(longRun, 3.0);
}

// A bolt that starts deep in a 3-wide slot cut into a block, the target in the open below: the
// slot's depth does not change how densely the bolt fills it.
TEST(StiffLightning, PocketDepthDoesNotChangeGrowthInIt) {
  auto pocket = [](int depth) {
    Params p;
    p.width = 33;
    p.height = depth + 40;
    p.method = Method::kDbm;
    p.obstacles.assign(size_t(p.width) * size_t(p.height), 0);
    for (int y = 0; y < depth; ++y)
      for (int x = 0; x < p.width; ++x)
        if (x < 15 || x > 17) p.obstacles[size_t(y) * size_t(p.width) + size_t(x)] = 1;
    p.start = {16, 0};
    p.targets = {{16, p.height - 1}};
    return p;
  };
  auto inSlot = [&](int depth, int seeds) {
    double sum = 0;
    for (int s = 1; s <= seeds; ++s) {
      Params p = pocket(depth);
      p.seed = uint64_t(s);
      auto r = grow(p);
      EXPECT_TRUE(r.ok());
      if (!r.ok()) return 0.0;
      size_t n = 0;
      for (const Node& nd : r.value().nodes) n += nd.cell.y < depth;
      sum += double(n) / depth;
    }
    return sum / seeds;
  };
  const double shallow = inSlot(48, 4), deep = inSlot(400, 2);
  printf("cells per row in the slot: %.3f at depth 48, %.3f at depth 400\n", shallow, deep);
  EXPECT_NEAR(deep / shallow, 1.0, 0.12);
}

// A bolt sealed off from its target for the 5-point Laplacian (a diamond of one-cell diagonal
// walls, which the 8-neighbourhood crosses): no field reaches the candidates, so DBM grows as it
// does with no field (uniformly) until it crosses, without cutting stages after rounding.
TEST(StiffLightning, SealedOffBoltGrowsWithoutAField) {
  Params p;
  p.width = p.height = 33;
  p.method = Method::kDbm;
  p.obstacles.assign(33 * 33, 0);
  for (int y = 0; y < 33; ++y)
    for (int x = 0; x < 33; ++x)
      if (std::abs(x - 16) + std::abs(y - 16) == 6) p.obstacles[size_t(y) * 33 + size_t(x)] = 1;
  p.start = {16, 16};
  p.targets = {{16, 32}};
  for (uint64_t seed : {1, 2, 3}) {
    p.seed = seed;
    auto r = grow(p);
    ASSERT_TRUE(r.ok()) << r.error().field << ": " << r.error().message;
    EXPECT_EQ(r.value().stats.counters.at("deepestStage"), 0.0);
    EXPECT_EQ(r.value().nodes.back().cell, (Cell{16, 32}));
  }
}

// The shape measure sees a bolt that fills its channel: against exact DBM in a 3 x 256 channel,
// other DBM seeds are indistinguishable (every measure within 4 standard errors) and Eden growth
// (eta 0: the filled channel that exact DBM returned before DeepField) is far off.
TEST(StiffLightning, ShapeDistanceSeesAFilledChannel) {
  auto shapes = [](double eta, uint64_t first, int n) {
    std::vector<BoltShape> out;
    for (uint64_t s = first; s < first + uint64_t(n); ++s) {
      auto r = grow(channel(3, 256, eta, s));
      EXPECT_TRUE(r.ok());
      if (r.ok()) out.push_back(shapeOf(r.value(), 3, 256));
    }
    return out;
  };
  const auto ref = shapes(2, 1, 6);
  const ShapeDistance same = shapeDistance(shapes(2, 101, 6), ref), filled = shapeDistance(shapes(0, 1, 6), ref);
  printf("other DBM seeds: z cells %.2f, tips %.2f, D %.2f; filled: z cells %.1f (%.0f against %.0f), tips %.1f, D %.1f\n",
         same.cells, same.tips, same.dimension, filled.cells, filled.mean.cells, filled.refMean.cells, filled.tips,
         filled.dimension);
  EXPECT_LT(same.worst, 4.0);
  EXPECT_GT(filled.worst, 10.0);
  EXPECT_GT(filled.cells, 10.0);
}

// eta -> 0 is uniform growth (Eden): at eta 1e-6 every weight is within 1e-3 of 1, even for
// candidates whose potential underflows (none may drop out), so the bolt fills the channel as
// densely as at eta 0.
TEST(StiffLightning, TinyEtaIsUniformGrowth) {
  for (int length : {64, 600}) {
    const double uniform = cellsPerRow(channel(3, length, 0, 1), 3);
    const double tiny = cellsPerRow(channel(3, length, 1e-6, 1), 3);
    printf("length %d: cells per row %.3f at eta 0, %.3f at eta 1e-6\n", length, uniform, tiny);
    EXPECT_NEAR(tiny / uniform, 1.0, 0.05) << "length " << length;
  }
}

// eta 50 is the strongest field line: an almost straight bolt, the same from every seed.
TEST(StiffLightning, HugeEtaIsAStraightBolt) {
  for (int length : {64, 1024}) {
    Params p = channel(5, length, 50, 1);
    for (uint64_t s : {1, 2}) {
      p.seed = s;
      auto r = grow(p);
      ASSERT_TRUE(r.ok());
      EXPECT_LE(r.value().nodes.size(), size_t(length + 2)) << "length " << length;
    }
  }
  Params open;
  open.method = Method::kDbm;
  open.width = open.height = 64;
  open.start = {32, 0};
  open.targets = {{32, 63}};
  open.eta = 50;
  auto r = grow(open);
  ASSERT_TRUE(r.ok());
  EXPECT_LE(r.value().nodes.size(), 70u);
}

// The potentials DeepField gives the candidates of a bolt 1300 cells from its target in a 3-wide
// channel (Phi ~ 1e-300 and below: the double solve underflows) against a long double solve of
// the same linear system by banded elimination.
TEST(StiffLightning, DeepFieldMatchesALongDoubleSolve) {
  if (LDBL_MAX_10_EXP < 1000) GTEST_SKIP() << "long double has double's range here: no reference below 1e-308";
  const int w = 3, h = 1400, tipRow = 100;
  std::vector<Cell> bolt;
  for (int y = 0; y <= tipRow; ++y) bolt.push_back({1, y});
  bolt.push_back({0, 40});  // a side branch: candidates behind the tip too
  const Cell target{1, h - 1};
  std::vector<uint8_t> fixedAt(size_t(w) * h, 0);
  for (const Cell& c : bolt) fixedAt[size_t(c.y) * w + size_t(c.x)] = 1;
  fixedAt[size_t(target.y) * w + size_t(target.x)] = 2;

  // The 5-point system on all cells, fixed cells as identity rows; bandwidth w.
  const int n = w * h, bw = w;
  std::vector<long double> band(size_t(n) * size_t(2 * bw + 1), 0.0L), rhs(size_t(n), 0.0L);
  auto a = [&](int i, int j) -> long double& { return band[size_t(i) * size_t(2 * bw + 1) + size_t(j - i + bw)]; };
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const int i = y * w + x;
      if (fixedAt[size_t(i)]) {
        a(i, i) = 1;
        rhs[size_t(i)] = fixedAt[size_t(i)] == 2 ? 1.0L : 0.0L;
        continue;
      }
      a(i, i) = 4;
      if (x > 0) a(i, i - 1) = -1;
      if (x + 1 < w) a(i, i + 1) = -1;
      if (y > 0) a(i, i - w) = -1;
      if (y + 1 < h) a(i, i + w) = -1;
    }
  for (int k = 0; k < n; ++k)  // no pivoting: diagonally dominant
    for (int i = k + 1; i <= std::min(n - 1, k + bw); ++i) {
      const long double m = a(i, k) / a(k, k);
      if (m == 0) continue;
      for (int j = k; j <= std::min(n - 1, k + bw); ++j) a(i, j) -= m * a(k, j);
      rhs[size_t(i)] -= m * rhs[size_t(k)];
    }
  std::vector<long double> phi(static_cast<size_t>(n), 0.0L);
  for (int i = n - 1; i >= 0; --i) {
    long double s = rhs[size_t(i)];
    for (int j = i + 1; j <= std::min(n - 1, i + bw); ++j) s -= a(i, j) * phi[size_t(j)];
    phi[size_t(i)] = s / a(i, i);
  }

  detail::DeepField field(std::make_unique<detail::Laplace>(w, h), w, h, 0);
  for (const Cell& c : bolt) field.fix(c, 0.0);
  field.fix(target, 1.0);
  std::vector<Cell> probes;
  for (const Cell& c : bolt)
    for (Cell d : {Cell{c.x - 1, c.y}, Cell{c.x + 1, c.y}, Cell{c.x, c.y - 1}, Cell{c.x, c.y + 1}})
      if (d.x >= 0 && d.x < w && d.y >= 0 && d.y < h && !fixedAt[size_t(d.y) * w + size_t(d.x)]) probes.push_back(d);
  std::vector<double> logPhi;
  field.solve(Solver::kMgpcg, 1e-6, probes, logPhi);
  EXPECT_GT(field.deepestStage(), 10);
  long double topRef = -INFINITY;
  double top = -INFINITY;
  for (size_t i = 0; i < probes.size(); ++i) {
    topRef = std::max(topRef, logl(phi[size_t(probes[i].y) * w + size_t(probes[i].x)]));
    top = std::max(top, logPhi[i]);
  }
  printf("largest candidate potential: 1e%.1Lf (long double), 1e%.1f (DeepField, %d stages)\n", topRef / logl(10.0L),
         top / std::log(10.0), field.deepestStage());
  EXPECT_NEAR(double(topRef), top, 1e-3 * std::fabs(double(topRef)));
  // The draw probabilities at eta 1, each relative to the largest: within 1e-5.
  for (size_t i = 0; i < probes.size(); ++i) {
    const double ref = double(logl(phi[size_t(probes[i].y) * w + size_t(probes[i].x)]) - topRef);
    EXPECT_NEAR(std::exp(logPhi[i] - top), std::exp(ref), 1e-5) << "probe " << probes[i].x << "," << probes[i].y;
  }
}

}  // namespace
