// bench/half_field.h, the candidate law of docs/lightning-shape.md ("What a law would have to
// do"): its neighbour counts on a known configuration, its coarse field's boundary values and
// screening, and a bolt grown by it (a tree from the start to the target, the same for a seed).
#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include "half_field.h"

namespace bench::shape {
namespace {

lt::Params openLayout(int s) {
  lt::Params p;
  p.width = p.height = s;
  p.start = {s / 2, 1};
  p.targets = {{s / 2, s - 2}};
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
  const lt::Cell t = f.at(p.targets[0].x, p.targets[0].y), s = f.at(32, 10);
  EXPECT_DOUBLE_EQ(f.phi[size_t(t.y) * 32 + size_t(t.x)], 1.0);
  EXPECT_DOUBLE_EQ(f.phi[size_t(s.y) * 32 + size_t(s.x)], 0.0);
  // Ahead of the channel's tip the field is larger than beside its root.
  EXPECT_GT(f.logAround(32, 32), f.logAround(35, 3));
  // A cell whose coarse neighbourhood the bolt fills gets the smallest nonzero field: finite.
  std::vector<lt::Cell> block;
  for (int y = 0; y < 12; ++y)
    for (int x = 20; x < 44; ++x) block.push_back({x, y});
  const CoarseField g(p, block, 2);
  EXPECT_TRUE(std::isfinite(g.logAround(32, 4)));
  EXPECT_LT(g.logAround(32, 4), g.logAround(32, 40));
}

TEST(HalfField, GrowsATreeFromTheStartToTheTargetTheSameForASeed) {
  lt::Params p = openLayout(48);
  p.seed = 7;
  const lt::Bolt a = growHalfField(p), b = growHalfField(p);
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
  const lt::Bolt c = growHalfField(p);
  bool differs = c.nodes.size() != a.nodes.size();
  for (size_t i = 0; !differs && i < a.nodes.size(); ++i) differs = !(a.nodes[i].cell == c.nodes[i].cell);
  EXPECT_TRUE(differs);
}

}  // namespace
}  // namespace bench::shape
