// bench/half_field.h, the candidate law of docs/lightning-shape.md ("What a law would have to
// do"): its neighbour counts and exposure on known configurations, its coarse field's boundary
// values and screening, the geodesic distance around a wall, and bolts grown by it with and
// without the field (a tree from the start to the target, the same for a seed).
#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "half_field.h"
#include "layouts.h"

namespace bench::shape {
namespace {

// The shape bench's open layout at eta 2.
lt::Params openLayout(int s) {
  lt::Params p = layout("open", s);
  p.eta = 2;
  return p;
}

TEST(HalfField, ScreeningCountsTheBoltAroundACell) {
  const int w = 32, h = 32;
  std::vector<int> stepAt(size_t(w) * size_t(h), -1);
  for (int x = 0; x <= 20; ++x) stepAt[size_t(10) * size_t(w) + size_t(x)] = x;  // a row, grown left to right
  const Screening s = screening(stepAt, w, h, 10, 11);
  EXPECT_EQ(s.n1, 3);     // (9..11, 10)
  EXPECT_EQ(s.n4, 1);     // (10, 10)
  EXPECT_EQ(s.n3, 7);     // (7..13, 10)
  EXPECT_EQ(s.last, 11);  // the latest of the three
  const Screening far = screening(stepAt, w, h, 10, 20);
  EXPECT_EQ(far.n1 + far.n3, 0);
}

TEST(HalfField, CoarseFieldHoldsItsBoundaryAndScreensBehindTheBolt) {
  const lt::Params p = openLayout(64);
  std::vector<lt::Cell> bolt;
  for (int y = 1; y < 30; ++y) bolt.push_back({32, y});  // a channel down the middle
  const CoarseField f(p, bolt, 2);
  ASSERT_EQ(f.phi.size(), size_t(32 * 32));
  EXPECT_DOUBLE_EQ(f.phi[f.grid.index(f.grid.target)], 1.0);
  EXPECT_DOUBLE_EQ(f.phi[f.grid.index(f.grid.at(32, 10))], 0.0);
  // Ahead of the channel's tip the field is larger than beside its root.
  EXPECT_GT(f.logAround(32, 32, 1e-300), f.logAround(35, 3, 1e-300));
  // A cell whose coarse neighbourhood the bolt fills gets the smallest field read around the
  // candidates: finite, and below the others'.
  std::vector<lt::Cell> block;
  for (int y = 0; y < 12; ++y)
    for (int x = 20; x < 44; ++x) block.push_back({x, y});
  const CoarseField g(p, block, 2);
  const std::vector<lt::Cell> candidates{{32, 4}, {32, 12}, {19, 6}};
  const double smallest = g.smallestAround(candidates);
  EXPECT_GT(smallest, 0.0);
  EXPECT_DOUBLE_EQ(g.logAround(32, 4, smallest), std::log(smallest));
  EXPECT_LT(g.logAround(32, 4, smallest), g.logAround(32, 12, smallest));
}

TEST(HalfField, GrowingCoarseFieldIsTheFieldSolvedFromScratch) {
  lt::Params p = openLayout(64);
  p.obstacles.assign(64 * 64, 0);
  for (int y = 40; y < 42; ++y)
    for (int x = 10; x < 40; ++x) p.obstacles[size_t(y) * 64 + size_t(x)] = 1;  // a wall, whole coarse cells
  GrowingCoarseField growing(p, 2);
  std::vector<lt::Cell> bolt, around;
  for (int y = 1; y < 30; ++y) {
    bolt.push_back({32 + y / 4, y});
    growing.add(bolt.back());
  }
  for (int y = 2; y < 31; ++y) around.push_back({33 + y / 4, y});
  const CoarseField scratch(p, bolt, 2), incremental = growing.solve(around);
  for (const lt::Cell& c : around)
    EXPECT_NEAR(incremental.logAround(c.x, c.y, 1e-300), scratch.logAround(c.x, c.y, 1e-300), 1e-6)
        << c.x << "," << c.y;
}

// A bolt grown by the law is a tree of 8-neighbour steps from the start to the target, each
// cell once, the same for a seed and not for another.
void expectGrowsATree(const HalfFieldLaw& law) {
  lt::Params p = openLayout(48);
  p.seed = 7;
  const lt::Bolt a = growHalfField(p, law), b = growHalfField(p, law);
  ASSERT_GE(a.nodes.size(), size_t(46));  // at least the straight path
  EXPECT_TRUE(a.nodes.front().cell == p.start);
  EXPECT_TRUE(a.nodes.back().cell == p.targets[0]);
  std::set<std::tuple<int, int>> seen;
  for (size_t i = 0; i < a.nodes.size(); ++i) {
    const lt::Node& n = a.nodes[i];
    EXPECT_TRUE(seen.insert({n.cell.x, n.cell.y}).second) << "cell " << n.cell.x << "," << n.cell.y << " twice";
    if (i == 0) continue;
    ASSERT_GE(n.parent, 0);
    ASSERT_LT(size_t(n.parent), i);
    const lt::Cell q = a.nodes[size_t(n.parent)].cell;
    EXPECT_LE(std::max(std::abs(q.x - n.cell.x), std::abs(q.y - n.cell.y)), 1);
  }
  ASSERT_EQ(a.nodes.size(), b.nodes.size());
  for (size_t i = 0; i < a.nodes.size(); ++i) EXPECT_TRUE(a.nodes[i].cell == b.nodes[i].cell);
  p.seed = 8;
  const lt::Bolt c = growHalfField(p, law);
  bool differs = c.nodes.size() != a.nodes.size();
  for (size_t i = 0; !differs && i < a.nodes.size(); ++i) differs = !(a.nodes[i].cell == c.nodes[i].cell);
  EXPECT_TRUE(differs);
}

TEST(HalfField, GrowsATreeFromTheStartToTheTargetTheSameForASeed) { expectGrowsATree({}); }

TEST(HalfField, GrowsATreeWithoutTheFieldByExposure) {
  HalfFieldLaw law;  // docs/lightning-shape.md, item 4: eta 2's single-step constants
  law.phi = 0;
  law.n1 = -0.013, law.n4 = -0.344, law.n3 = -0.105, law.free = 2.02, law.g = 0.0676, law.p = -1.61;
  expectGrowsATree(law);
}

TEST(HalfField, ExposureIsTheMeanFreeLengthOfItsRays) {
  const int w = 64, h = 64;
  std::vector<int> stepAt(size_t(w) * size_t(h), -1);
  const std::vector<uint8_t> none;
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 32, 32, 16), 16.0);  // nothing within reach
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 32, 32, 8), 8.0);
  // At the border: 8 rays travel 16; of the 8 leaving, the two nearest the border travel 2 cells
  // along it first, the rest none: (8 * 16 + 2 * 2) / 16.
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 0, 32, 16), 8.25);
  for (int y = 0; y < h; ++y) stepAt[size_t(y) * size_t(w) + 30] = y;  // a bolt column at x = 30
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 31, 32, 16), 8.25);  // beside the bolt: as at the border
  std::vector<uint8_t> walls(size_t(w) * size_t(h), 0);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) walls[size_t(40 + dy) * size_t(w) + size_t(40 + dx)] = dx != 0 || dy != 0;
  EXPECT_DOUBLE_EQ(exposure(stepAt, walls, w, h, 40, 40, 16), 0.5);  // walled in: the floor
}

TEST(HalfField, GeodesicGoesAroundTheObstacles) {
  lt::Params p;
  p.width = 32, p.height = 32;
  p.targets = {{16, 30}};
  auto octile = [](int dx, int dy) {
    const double a = std::abs(dx), b = std::abs(dy);
    return std::max(a, b) + (std::sqrt(2.0) - 1) * std::min(a, b);
  };
  const std::vector<double> open = geodesic(p);
  EXPECT_NEAR(open[size_t(10) * 32 + 3], octile(13, 20), 1e-9);
  p.obstacles.assign(32 * 32, 0);
  for (int x = 0; x <= 24; ++x) p.obstacles[size_t(20) * 32 + size_t(x)] = 1;  // a wall with a gap at x >= 25
  const std::vector<double> around = geodesic(p);
  EXPECT_NEAR(around[size_t(10) * 32 + 16], octile(9, 10) + octile(9, 10), 1e-9);  // through (25, 20)
  EXPECT_TRUE(std::isinf(around[size_t(20) * 32 + 5]));                             // in the wall
}

}  // namespace
}  // namespace bench::shape
