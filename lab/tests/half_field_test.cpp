// lab/half_field.h, the candidate law of docs/lightning-shape.md ("What a law would have to
// do"): its neighbour counts on a known configuration, its coarse field's boundary values and
// screening, and bolts grown by it, with exposure and without (a tree from the start to the
// target, the same for a seed).
#include <cmath>

#include <gtest/gtest.h>

#include "grown_bolt.h"
#include "half_field.h"

namespace bench::shape {
namespace {

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

TEST(HalfField, GrowsATreeFromTheStartToTheTargetTheSameForASeed) {
  expectGrowsATree(openLayout(48), [](const lt::Params& p) { return growHalfField(p); });
}

TEST(HalfField, GrowsATreeWithExposure) {
  HalfFieldLaw law;
  law.free = 1.0;
  expectGrowsATree(openLayout(48), [&](const lt::Params& p) { return growHalfField(p, law); });
}

}  // namespace
}  // namespace bench::shape
