// Target regions (Params::targetRegion): the strike ends on whichever region cell the bolt
// touches. Checked by invariance (a one-cell region is its point target, bit for bit, for
// every method, in 2-D and 3-D), by the tree's form, by the region's physics (DBM's strikes
// over the ground spread; a point target's do not), and by the errors naming their fields.
#include <cmath>
#include <random>
#include <set>

#include <gtest/gtest.h>

#include <effects/lightning.h>

#include "lightning/hooks.h"

#include "lightning/nearest.h"

namespace effects::lightning {
namespace {

std::vector<uint8_t> groundOf(int w, int h, int d = 0) {
  std::vector<uint8_t> r(size_t(w) * size_t(h) * size_t(std::max(d, 1)), 0);
  for (int z = 0; z < std::max(d, 1); ++z)
    for (int x = 0; x < w; ++x) r[(size_t(z) * size_t(h) + size_t(h - 1)) * size_t(w) + size_t(x)] = 1;
  return r;
}

Params ground(int n, Method m, uint64_t seed = 1) {
  Params p;
  p.width = p.height = n;
  p.start = {n / 2, 0};
  p.targets.clear();
  p.targetRegion = groundOf(n, n);
  p.method = m;
  p.seed = seed;
  calibrate(p);
  return p;
}

bool sameBolt(const Bolt& a, const Bolt& b) {
  if (a.nodes.size() != b.nodes.size() || a.mainChannel != b.mainChannel) return false;
  for (size_t i = 0; i < a.nodes.size(); ++i)
    if (!(a.nodes[i].cell == b.nodes[i].cell) || a.nodes[i].parent != b.nodes[i].parent) return false;
  return true;
}

TEST(TargetRegion, OneCellRegionIsItsPointTargetBitForBit) {
  for (int depth : {0, 12})
    for (Method m : {Method::kFast, Method::kDbm, Method::kCharges}) {
      if (depth && m == Method::kCharges) continue;
      Params point;
      point.width = point.height = depth ? 12 : 40;
      point.depth = depth;
      point.neighbourhood = depth ? 26 : 8;
      point.start = {5, 0, depth ? 6 : 0};
      point.targets = {{depth ? 8 : 30, point.height - 1, depth ? 4 : 0}};
      point.method = m;
      point.seed = 7;
      calibrate(point);
      Params region = point;
      region.targets.clear();
      region.targetRegion.assign(size_t(point.width) * size_t(point.height) * size_t(std::max(depth, 1)), 0);
      const Cell t = point.targets[0];
      region.targetRegion[(size_t(t.z) * size_t(point.height) + size_t(t.y)) * size_t(point.width) + size_t(t.x)] = 1;
      auto a = grow(point), b = grow(region);
      ASSERT_TRUE(a.ok() && b.ok()) << toString(m);
      EXPECT_TRUE(sameBolt(a.value(), b.value())) << toString(m) << " depth " << depth;
    }
}

TEST(TargetRegion, EveryMethodStrikesTheGroundOnce) {
  for (Method m : {Method::kFast, Method::kDbm, Method::kCharges}) {
    const Params p = ground(48, m, 3);
    auto r = grow(p);
    ASSERT_TRUE(r.ok()) << r.error().message;
    const Bolt& b = r.value();
    std::set<std::pair<int, int>> seen;
    int inRegion = 0;
    for (size_t i = 0; i < b.nodes.size(); ++i) {
      const Cell c = b.nodes[i].cell;
      EXPECT_TRUE(seen.insert({c.x, c.y}).second);
      inRegion += c.y == p.height - 1;
      if (i) {
        const Cell q = b.nodes[size_t(b.nodes[i].parent)].cell;
        EXPECT_LE(std::max(std::abs(q.x - c.x), std::abs(q.y - c.y)), 1);
      }
    }
    EXPECT_EQ(inRegion, 1) << toString(m);  // the struck cell, and no other region cell
    EXPECT_EQ(b.nodes[size_t(b.mainChannel.back())].cell.y, p.height - 1);
    EXPECT_EQ(b.nodes[size_t(b.mainChannel.back())].step, int(b.nodes.size()) - 1);  // the last cell grown
  }
}

// DBM over the ground holds the whole bottom row at Phi = 1: the strike lands where the bolt
// happens to get close, so over seeds the struck column spreads. Fast (P towards the region's
// nearest cell, the axis straight down) must spread too, not fall on the cell below the start.
TEST(TargetRegion, StrikesOnTheGroundSpreadForDbmAndFast) {
  for (Method m : {Method::kDbm, Method::kFast}) {
    std::set<int> columns;
    for (uint64_t seed = 1; seed <= 12; ++seed) {
      auto r = grow(ground(48, m, seed));
      ASSERT_TRUE(r.ok());
      columns.insert(r.value().nodes[size_t(r.value().mainChannel.back())].cell.x);
    }
    EXPECT_GE(columns.size(), 6u) << toString(m);
  }
}

TEST(TargetRegion, ChainTargetsThenTheRegion) {
  Params p = ground(48, Method::kFast);
  p.targets = {{10, 20}};
  auto r = grow(p);
  ASSERT_TRUE(r.ok()) << r.error().message;
  const Bolt& b = r.value();
  bool through = false;
  for (int n : b.mainChannel) through = through || b.nodes[size_t(n)].cell == Cell{10, 20};
  EXPECT_TRUE(through);
  EXPECT_EQ(b.nodes[size_t(b.mainChannel.back())].cell.y, 47);
}

TEST(TargetRegion, ErrorsNameTheirField) {
  Params p = ground(32, Method::kFast);
  p.start = {5, 31};
  EXPECT_EQ(grow(p).error().field, "/start");
  p = ground(32, Method::kFast);
  p.targets = {{4, 31}};
  EXPECT_EQ(grow(p).error().field, "/targets/0");
  p = ground(32, Method::kFast);
  p.targetRegion.pop_back();
  EXPECT_EQ(validate(p)->field, "/targetRegion");
  p = ground(32, Method::kFast);
  p.obstacles = p.targetRegion;  // every region cell blocked
  EXPECT_EQ(grow(p).error().field, "/targetRegion");
  p = ground(32, Method::kDbm);
  p.obstacles.assign(32 * 32, 0);
  for (int x = 0; x < 32; ++x) p.obstacles[size_t(20) * 32 + size_t(x)] = 1;  // a wall across
  auto r = grow(p);
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().field, "/targetRegion");
  EXPECT_EQ(r.error().kind, ErrorKind::kUnsatisfiable);
  p.targetRegion.clear();
  EXPECT_EQ(validate(p)->field, "/targets");  // neither targets nor a region
}

TEST(TargetRegion, AStarReachesTheNearestReachableRegionCell) {
  // Two region cells: (2, 10) behind a wall, (18, 10) open; from (2, 0) the open one is
  // reached, by the shortest path there.
  const int w = 20, h = 12;
  std::vector<uint8_t> obstacles(size_t(w * h), 0), goals(size_t(w * h), 0);
  for (int x = 0; x < 6; ++x) obstacles[size_t(8 * w + x)] = 1;
  for (int y = 8; y < h; ++y) obstacles[size_t(y * w + 6)] = 1;
  goals[size_t(10 * w + 2)] = goals[size_t(10 * w + 18)] = 1;
  auto path = astarToRegion(w, h, obstacles, {2, 0}, goals);
  ASSERT_FALSE(path.empty());
  EXPECT_EQ(path.back(), (Cell{18, 10}));
  EXPECT_EQ(path.size(), astar(w, h, obstacles, {2, 0}, {18, 10}).size());
  obstacles[size_t(10 * w + 18)] = 0;
  for (int y = 0; y < h; ++y) obstacles[size_t(y * w + 10)] = 1;  // cut off the open one
  path = astarToRegion(w, h, obstacles, {2, 0}, goals);
  EXPECT_TRUE(path.empty());
}

TEST(TargetRegion, NearestCellsAgreesWithBruteForce) {
  std::mt19937 rng(5);
  for (int depth : {1, 9}) {
    const int w = 23, h = 17;
    std::vector<uint8_t> flags(size_t(w * h * depth), 0);
    for (auto& f : flags) f = rng() % 7 == 0;
    detail::NearestCells nearest(w, h, depth, flags);
    for (int q = 0; q < 300; ++q) {
      const Cell c{int(rng() % w), int(rng() % h), int(rng() % unsigned(depth))};
      double best = INFINITY;
      for (size_t i = 0; i < flags.size(); ++i)
        if (flags[i]) {
          const int x = int(i % w), y = int(i / w % h), z = int(i / (w * h));
          best = std::min(best, std::sqrt(double((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) + (z - c.z) * (z - c.z))));
        }
      EXPECT_DOUBLE_EQ(nearest.distance(c), best);
    }
  }
}

}  // namespace
}  // namespace effects::lightning
