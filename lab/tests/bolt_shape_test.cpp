// lab/bolt_shape.h, the shape statistics that compare bolts with DBM (lab/lightning_shape),
// on shapes whose answers are known: a straight line, a filled square, a comb.
#include <cmath>

#include <gtest/gtest.h>

#include "bolt_shape.h"

namespace bench::shape {
namespace {

// A bolt from cells in growth order, each grown from `parent` (-1 for the first).
lt::Bolt boltOf(const std::vector<std::pair<lt::Cell, int>>& cells) {
  lt::Bolt b;
  for (const auto& [cell, parent] : cells) b.nodes.push_back({cell, parent, int(b.nodes.size())});
  return b;
}

TEST(BoltShape, StraightLineHasDimensionOneTwoEndsAndOneSegment) {
  std::vector<std::pair<lt::Cell, int>> cells;
  for (int x = 0; x < 128; ++x) cells.push_back({{x, 10}, x - 1});
  const Measures m = measure(boltOf(cells), 128, 128);
  EXPECT_NEAR(slope(m.boxCounts), 1.0, 1e-9);
  EXPECT_EQ(m.boxCounts.front(), 128);
  EXPECT_EQ(m.leafTips, 1);       // the far end (the start is not a tip)
  EXPECT_EQ(m.neighbourTips, 2);  // both ends have one neighbour
  ASSERT_EQ(m.segments.size(), 1u);
  EXPECT_EQ(m.segments[0], 127);
  EXPECT_TRUE(m.angles.empty());
  EXPECT_EQ(m.massRadius.front(), 3);  // cells within 2 of the start: x = 0, 1, 2
}

TEST(BoltShape, FilledSquareHasDimensionTwo) {
  std::vector<std::pair<lt::Cell, int>> cells;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) cells.push_back({{y % 2 ? 63 - x : x, y}, int(cells.size()) - 1});  // a snake
  const Measures m = measure(boltOf(cells), 64, 64);
  EXPECT_NEAR(slope(m.boxCounts), 2.0, 1e-9);
  EXPECT_EQ(m.cells, 4096);
}

TEST(BoltShape, CombHasKnownTipsSegmentsAndRightAngles) {
  // A spine x = 0..40 along y = 0, and nine teeth of six cells up from x = 4, 8, ..., 36.
  std::vector<std::pair<lt::Cell, int>> cells;
  std::vector<int> spine(41);
  for (int x = 0; x <= 40; ++x) {
    spine[size_t(x)] = int(cells.size());
    cells.push_back({{x, 0}, x ? spine[size_t(x - 1)] : -1});
  }
  for (int x = 4; x <= 36; x += 4)
    for (int y = 1; y <= 6; ++y) cells.push_back({{x, y}, y == 1 ? spine[size_t(x)] : int(cells.size()) - 1});
  const Measures m = measure(boltOf(cells), 64, 64);
  EXPECT_EQ(m.leafTips, 10);       // nine teeth and the spine's end
  EXPECT_EQ(m.neighbourTips, 11);  // and the start, which has one neighbour
  std::vector<double> spineSegments, teeth;
  for (double s : m.segments) (s == 6 ? teeth : spineSegments).push_back(s);
  EXPECT_EQ(teeth.size(), 9u);
  EXPECT_EQ(spineSegments, std::vector<double>(10, 4.0));  // 1-4, 5-8, ..., 37-40
  ASSERT_EQ(m.angles.size(), 9u);
  for (double a : m.angles) EXPECT_NEAR(a, 90.0, 1e-9);
  // The library's per-response shape (include "shape") on the same comb: a tooth's root has
  // two children (the tooth and the spine's next cell).
  const lt::BoltShape shape = lt::shapeOf(boltOf(cells), 64, 64);
  EXPECT_EQ(shape.tips, 10);
  EXPECT_EQ(shape.branchPoints, 9);
  EXPECT_EQ(shape.cells, 41 + 54);
}

TEST(BoltShape, TwoSampleStatisticsSeeDifferencesAndNotTheirAbsence) {
  EXPECT_EQ(ks({1, 2, 3, 4}, {1, 2, 3, 4}), 0.0);
  EXPECT_EQ(ks({1, 2, 3}, {10, 11, 12}), 1.0);
  EXPECT_NEAR(ks({1, 2, 3, 4}, {3, 4, 5, 6}), 0.5, 1e-12);
  const std::vector<std::vector<double>> a = {{1, 10}, {2, 11}, {3, 12}}, b = {{1, 10}, {2, 11}, {3, 12}};
  EXPECT_EQ(curveZ(a, b), 0.0);
  const std::vector<std::vector<double>> c = {{1, 20}, {2, 21}, {3, 22}};
  EXPECT_NEAR(curveZ(a, c), 10.0 / std::sqrt(2.0 / 3.0), 1e-9);  // second point: 10 apart, s.e. sqrt(1/3 + 1/3)
}

}  // namespace
}  // namespace bench::shape
