// lab/exposure_law.h, the law without a field of docs/lightning-shape.md ("What a law would
// have to do", item 4): exposure and the geodesic distance on configurations with known
// answers, the exposure the grower keeps step by step against exposure() from scratch, and
// bolts grown by it (a tree from the start to the target, the same for a seed).
#include <cmath>

#include <gtest/gtest.h>

#include "exposure_law.h"
#include "grown_bolt.h"
#include "layouts.h"

namespace bench::shape {
namespace {

TEST(ExposureLaw, GrowsATreeFromTheStartToTheTargetTheSameForASeed) {
  expectGrowsATree(openLayout(48), [](const lt::Params& p) { return growExposureLaw(p); });
  lt::Params wall = layout("wall", 64);
  wall.eta = 2;
  expectGrowsATree(wall, [](const lt::Params& p) { return growExposureLaw(p); });
}

// The grower keeps each candidate's rays as the bolt grows; at every step they must give what
// exposure() gives from scratch, over a wall (obstacles stop rays too).
TEST(ExposureLaw, KeptExposureIsExposureFromScratch) {
  lt::Params p = layout("wall", 64);
  p.eta = 1;
  p.seed = 3;
  const Rays rays(16);
  size_t checked = 0, wrong = 0;
  const lt::Bolt bolt = growExposureLaw(p, {}, [&](const std::vector<int>& stepAt, lt::Cell c, double kept) {
    ++checked;
    wrong += kept != exposure(stepAt, p.obstacles, p.width, p.height, c.x, c.y, rays);
  });
  EXPECT_GT(bolt.nodes.size(), size_t(60));
  EXPECT_GT(checked, size_t(1000));
  EXPECT_EQ(wrong, size_t(0));
}

TEST(ExposureLaw, ExposureIsTheMeanFreeLengthOfItsRays) {
  const int w = 64, h = 64;
  std::vector<int> stepAt(size_t(w) * size_t(h), -1);
  const std::vector<uint8_t> none;
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 32, 32, Rays(16)), 16.0);  // nothing within reach
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 32, 32, Rays(8)), 8.0);
  // At the border: 8 rays travel 16; of the 8 leaving, the two nearest the border travel 2 cells
  // along it first, the rest none: (8 * 16 + 2 * 2) / 16.
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 0, 32, Rays(16)), 8.25);
  for (int y = 0; y < h; ++y) stepAt[size_t(y) * size_t(w) + 30] = y;      // a bolt column at x = 30
  EXPECT_DOUBLE_EQ(exposure(stepAt, none, w, h, 31, 32, Rays(16)), 8.25);  // beside the bolt: as at the border
  std::vector<uint8_t> walls(size_t(w) * size_t(h), 0);
  for (int dy = -1; dy <= 1; ++dy)
    for (int dx = -1; dx <= 1; ++dx) walls[size_t(40 + dy) * size_t(w) + size_t(40 + dx)] = dx != 0 || dy != 0;
  EXPECT_DOUBLE_EQ(exposure(stepAt, walls, w, h, 40, 40, Rays(16)), 0.5);  // walled in: the floor
}

TEST(ExposureLaw, GeodesicGoesAroundTheObstacles) {
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
  EXPECT_TRUE(std::isinf(around[size_t(20) * 32 + 5]));                            // in the wall
}

}  // namespace
}  // namespace bench::shape
