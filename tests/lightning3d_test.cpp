// effects/lightning on 3-D grids: the octree boundary potential, the 7-point DBM solve, A* in
// 26 neighbours, conservative voxelisation, and bolts that stay out of obstacles.
#include <algorithm>
#include <array>
#include <cmath>
#include <set>
#include <tuple>

#include <gtest/gtest.h>

#include <effects/lightning.h>

#include "lightning/hooks.h"

#include "fixtures.h"

namespace effects::lightning {
namespace {

Params volume(int n, Method m = Method::kFast, uint64_t seed = 1) { return fixtures::volumeLayout(n, m, seed); }

size_t at(const Params& p, int x, int y, int z) { return (size_t(z) * size_t(p.height) + size_t(y)) * size_t(p.width) + size_t(x); }

// A tree of cells in the neighbourhood, free of obstacles, from start to every target.
void expectWellFormed(const Params& p, const Bolt& b) {
  ASSERT_FALSE(b.nodes.empty());
  EXPECT_EQ(b.nodes[0].cell, p.start);
  std::set<std::tuple<int, int, int>> seen;
  for (size_t i = 0; i < b.nodes.size(); ++i) {
    const Cell c = b.nodes[i].cell;
    ASSERT_TRUE(c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < p.width && c.y < p.height && c.z < p.depth);
    EXPECT_TRUE(seen.insert({c.x, c.y, c.z}).second) << "voxel twice";
    if (!p.obstacles.empty()) EXPECT_EQ(p.obstacles[at(p, c.x, c.y, c.z)], 0) << "inside an obstacle";
    if (i == 0) continue;
    const Cell q = b.nodes[size_t(b.nodes[i].parent)].cell;
    const int dx = std::abs(q.x - c.x), dy = std::abs(q.y - c.y), dz = std::abs(q.z - c.z);
    EXPECT_TRUE(dx <= 1 && dy <= 1 && dz <= 1 && dx + dy + dz > 0) << "not 26-connected";
    if (p.neighbourhood == 6) EXPECT_EQ(dx + dy + dz, 1);
  }
  for (const Cell& t : p.targets) EXPECT_TRUE(seen.count({t.x, t.y, t.z}));
}

TEST(Lightning3d, BoundaryPotentialMatchesTheDirectSum) {
  const int w = 20, h = 14, d = 11;
  std::vector<uint8_t> obstacles(size_t(w) * h * d, 0);
  for (int z = 3; z < 7; ++z)
    for (int x = 4; x < 15; ++x) obstacles[(size_t(z) * h + 7) * w + size_t(x)] = 1;
  for (Cell c : {Cell{1, 1, 1}, Cell{10, 3, 5}, Cell{18, 12, 9}, Cell{10, 8, 5}}) {
    double direct = 0;
    for (int z = -1; z <= d; ++z)
      for (int y = -1; y <= h; ++y)
        for (int x = -1; x <= w; ++x) {
          const bool shell = x < 0 || y < 0 || z < 0 || x == w || y == h || z == d;
          if (!shell && !obstacles[(size_t(z) * h + size_t(y)) * w + size_t(x)]) continue;
          direct += 1.0 / std::sqrt(double((x - c.x) * (x - c.x) + (y - c.y) * (y - c.y) + (z - c.z) * (z - c.z)));
        }
    EXPECT_NEAR(boundaryPotential(w, h, d, obstacles, c), direct, 0.02 * direct) << c.x << " " << c.y << " " << c.z;
  }
}

TEST(Lightning3d, AstarGoesThroughTheOnlyHoleOfASlab) {
  const int n = 24;
  std::vector<uint8_t> obstacles(size_t(n) * n * n, 0);
  for (int z = 0; z < n; ++z)
    for (int x = 0; x < n; ++x)
      if (!(x == 3 && z == 19)) obstacles[(size_t(z) * n + 12) * n + size_t(x)] = 1;  // slab y = 12, hole (3, 12, 19)
  for (int nb : {26, 6}) {
    auto path = astar(n, n, obstacles, {12, 0, 12}, {12, 23, 12}, nb, n);
    ASSERT_FALSE(path.empty());
    bool hole = false;
    for (size_t i = 0; i < path.size(); ++i) {
      EXPECT_EQ(obstacles[(size_t(path[i].z) * n + size_t(path[i].y)) * n + size_t(path[i].x)], 0);
      hole = hole || (path[i] == Cell{3, 12, 19});
      if (i) {
        const int dx = std::abs(path[i].x - path[i - 1].x), dy = std::abs(path[i].y - path[i - 1].y),
                  dz = std::abs(path[i].z - path[i - 1].z);
        EXPECT_TRUE(nb == 26 ? std::max({dx, dy, dz}) == 1 : dx + dy + dz == 1);
      }
    }
    EXPECT_TRUE(hole) << "neighbourhood " << nb;
  }
  obstacles[(size_t(19) * n + 12) * n + 3] = 1;  // the hole closed
  EXPECT_TRUE(astar(n, n, obstacles, {12, 0, 12}, {12, 23, 12}, 26, n).empty());
}

TEST(Lightning3d, EveryMethodGrowsThroughTheHole) {
  for (Method m : {Method::kFast, Method::kDbm}) {
    Params p = volume(24, m, 3);
    p.obstacles.assign(size_t(24) * 24 * 24, 0);
    for (int z = 0; z < 24; ++z)
      for (int x = 0; x < 24; ++x)
        if (!(x >= 3 && x <= 4 && z >= 18 && z <= 19)) p.obstacles[at(p, x, 12, z)] = 1;
    auto b = grow(p);
    ASSERT_TRUE(b.ok()) << b.error().message;
    expectWellFormed(p, b.value());
    bool through = false;
    for (const Node& n : b.value().nodes) through = through || (n.cell.y == 12);
    EXPECT_TRUE(through);
  }
}

TEST(Lightning3d, SixNeighboursAndChains) {
  Params p = volume(20, Method::kFast, 5);
  p.neighbourhood = 6;
  p.targets = {{10, 10, 2}, {2, 19, 17}};
  auto b = grow(p);
  ASSERT_TRUE(b.ok()) << b.error().message;
  expectWellFormed(p, b.value());
}

TEST(Lightning3d, SameRequestSameBolt) {
  for (Method m : {Method::kFast, Method::kDbm}) {
    Params p = volume(16, m, 9);
    auto a = grow(p), b = grow(p);
    ASSERT_TRUE(a.ok() && b.ok());
    ASSERT_EQ(a.value().nodes.size(), b.value().nodes.size());
    for (size_t i = 0; i < a.value().nodes.size(); ++i) EXPECT_EQ(a.value().nodes[i].cell, b.value().nodes[i].cell);
  }
}

// The boundary octree and its memo are cached per (size, obstacle set): a bolt grown on a warm
// map (its memo partly filled by another seed's bolt) is the bolt grown on a fresh one.
TEST(Lightning3d, CachedBoundaryOctreeGivesTheSameBolt) {
  Params p = volume(16);
  p.width = 37, p.height = 29, p.depth = 23;  // a size no other test uses: the first call builds
  p.start = {18, 0, 11};
  p.targets = {{18, 28, 11}};
  p.obstacles.assign(size_t(37) * 29 * 23, 0);
  p.obstacles[at(p, 5, 14, 5)] = 1;
  p.seed = 5;
  auto cold = grow(p);
  ASSERT_TRUE(cold.ok());
  EXPECT_EQ(cold.value().stats.counters.at("boundaryMapCached"), 0);
  Params other = p;
  other.seed = 6;
  ASSERT_TRUE(grow(other).ok());
  auto warm = grow(p);
  ASSERT_TRUE(warm.ok());
  EXPECT_EQ(warm.value().stats.counters.at("boundaryMapCached"), 1);
  ASSERT_EQ(cold.value().nodes.size(), warm.value().nodes.size());
  for (size_t i = 0; i < cold.value().nodes.size(); ++i) {
    EXPECT_EQ(cold.value().nodes[i].cell, warm.value().nodes[i].cell);
    EXPECT_EQ(cold.value().nodes[i].parent, warm.value().nodes[i].parent);
  }
  p.obstacles[at(p, 6, 14, 5)] = 1;  // another scene
  auto moved = grow(p);
  ASSERT_TRUE(moved.ok());
  EXPECT_EQ(moved.value().stats.counters.at("boundaryMapCached"), 0);
}

TEST(Lightning3d, DbmSolveConvergesToTheLaplaceSolution) {
  // The 7-point problem of a bolt: MGPCG's relative residual meets the tolerance, and its
  // potential equals plain CG's to the tolerance's scale.
  Params p = volume(17, Method::kDbm, 2);
  p.tolerance = 1e-9;
  p.solver = Solver::kMgpcg;
  auto mg = grow(p);
  ASSERT_TRUE(mg.ok());
  EXPECT_LE(mg.value().stats.counters.at("residual"), 1e-9);
  EXPECT_EQ(mg.value().stats.method, "dbm-mgpcg");
  p.solver = Solver::kCg;
  auto cg = grow(p);
  ASSERT_TRUE(cg.ok());
  EXPECT_LE(cg.value().stats.counters.at("residual"), 1e-9);
  // At this tolerance both see the same potential at every step, so the bolts agree.
  ASSERT_EQ(mg.value().nodes.size(), cg.value().nodes.size());
  for (size_t i = 0; i < mg.value().nodes.size(); ++i) EXPECT_EQ(mg.value().nodes[i].cell, cg.value().nodes[i].cell);
  EXPECT_LT(mg.value().stats.counters.at("solverIterations"), cg.value().stats.counters.at("solverIterations"));
}

TEST(Lightning3d, CapacitanceIsTheExactSolution) {
  // Boxes with each axis the longest once (the closed form runs along it), a wandering bolt
  // and scattered obstacles: the direct potential equals MGPCG converged to 1e-13 and is
  // 7-point harmonic off the fixed voxels to rounding.
  effects::Rng rng(5);
  for (const auto& size : {std::array<int, 3>{12, 16, 10}, {21, 9, 14}, {10, 11, 23}}) {
    const int w = size[0], h = size[1], d = size[2];
    std::vector<uint8_t> obstacles(size_t(w) * size_t(h) * size_t(d), 0);
    auto index = [&](int x, int y, int z) { return (size_t(z) * size_t(h) + size_t(y)) * size_t(w) + size_t(x); };
    for (int k = 0; k < 30; ++k) obstacles[size_t(rng.uniform() * double(obstacles.size()))] = 1;
    std::vector<Cell> bolt;
    Cell c{w / 2, 0, d / 2};
    for (int k = 0; k < 2 * h / 3; ++k) {
      bolt.push_back(c);
      obstacles[index(c.x, c.y, c.z)] = 0;
      c.x = std::clamp(c.x + int(rng.uniform() * 3) - 1, 0, w - 1);
      c.z = std::clamp(c.z + int(rng.uniform() * 3) - 1, 0, d - 1);
      c.y = std::min(c.y + 1, h - 2);
    }
    const Cell target{w / 3, h - 1, d / 3};
    obstacles[index(target.x, target.y, target.z)] = 0;
    int it = -1;
    double res = 1;
    auto a = solveLaplace(w, h, d, obstacles, bolt, target, Solver::kCapacitance, 1e-6, &it, &res);
    auto b = solveLaplace(w, h, d, obstacles, bolt, target, Solver::kMgpcg, 1e-13);
    EXPECT_EQ(it, 0) << "direct, no iterations";
    EXPECT_LE(res, 1e-12) << w << "x" << h << "x" << d;
    std::vector<uint8_t> fixed = obstacles;
    for (const Cell& f : bolt) fixed[index(f.x, f.y, f.z)] = 1;
    fixed[index(target.x, target.y, target.z)] = 1;
    auto at = [&](int x, int y, int z) {
      return (x < 0 || y < 0 || z < 0 || x >= w || y >= h || z >= d) ? 0.0 : a[index(x, y, z)];
    };
    double worst = 0, harmonic = 0;
    for (int z = 0; z < d; ++z)
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x) {
          const size_t i = index(x, y, z);
          worst = std::max(worst, std::fabs(a[i] - b[i]));
          if (fixed[i])
            EXPECT_EQ(a[i], x == target.x && y == target.y && z == target.z ? 1.0 : 0.0);
          else
            harmonic = std::max(harmonic, std::fabs(6 * at(x, y, z) - at(x - 1, y, z) - at(x + 1, y, z) -
                                                    at(x, y - 1, z) - at(x, y + 1, z) - at(x, y, z - 1) -
                                                    at(x, y, z + 1)));
        }
    EXPECT_LE(worst, 1e-11) << w << "x" << h << "x" << d;
    EXPECT_LE(harmonic, 1e-12) << w << "x" << h << "x" << d;
  }
}

TEST(Lightning3d, CapacitanceGrowsMgpcgsBolts) {
  // The default 3-D dbm solver is exact: seed for seed, the bolts MGPCG grows converged.
  for (uint64_t seed = 1; seed <= 4; ++seed) {
    Params p = volume(20, Method::kDbm, 2);
    p.seed = seed;
    auto direct = grow(p);
    ASSERT_TRUE(direct.ok());
    EXPECT_EQ(direct.value().stats.method, "dbm-capacitance");
    p.solver = Solver::kMgpcg;
    p.tolerance = 1e-10;
    auto mg = grow(p);
    ASSERT_TRUE(mg.ok());
    ASSERT_EQ(direct.value().nodes.size(), mg.value().nodes.size()) << "seed " << seed;
    for (size_t i = 0; i < mg.value().nodes.size(); ++i)
      EXPECT_EQ(direct.value().nodes[i].cell, mg.value().nodes[i].cell) << "seed " << seed;
  }
}

TEST(Lightning3d, ErrorsNameTheField) {
  Params p = volume(16);
  p.neighbourhood = 8;
  EXPECT_EQ(grow(p).error().field, "/neighbourhood");
  p = volume(16);
  p.method = Method::kCharges;
  EXPECT_EQ(grow(p).error().field, "/method");
  p = volume(16);
  p.targets = {{8, 15, 16}};
  EXPECT_EQ(grow(p).error().field, "/targets/0");
  p = volume(16);
  p.obstacles.assign(size_t(16) * 16 * 16, 0);
  p.obstacles[at(p, 8, 0, 8)] = 1;
  EXPECT_EQ(grow(p).error().kind, ErrorKind::kUnsatisfiable);
  p = volume(16);
  p.obstacles.assign(16 * 16, 0);
  EXPECT_EQ(grow(p).error().field, "/obstacles");
}

TEST(Lightning3d, VoxelisationIsConservative) {
  // One triangle in the plane z = 4.5 over x, y in [2, 10]: every voxel of layer z = 4 whose
  // square meets the triangle is blocked, nothing in other layers.
  const int n = 12;
  std::vector<uint8_t> grid(size_t(n) * n * n, 0);
  voxelizeTriangles(n, n, n, {2, 2, 4.5, 10, 2, 4.5, 2, 10, 4.5}, {0, 1, 2}, grid);
  for (int z = 0; z < n; ++z)
    for (int y = 0; y < n; ++y)
      for (int x = 0; x < n; ++x) {
        const bool meets = z == 4 && x + 1 >= 2 && y + 1 >= 2 && x <= 10 && y <= 10 && x + y <= 12;  // x + y <= 12 at the closed corner
        EXPECT_EQ(grid[(size_t(z) * n + size_t(y)) * n + size_t(x)] != 0, meets) << x << " " << y << " " << z;
      }
  // A triangle along a space diagonal blocks a 26-connected chain of voxels from end to end.
  std::vector<uint8_t> diag(size_t(n) * n * n, 0);
  voxelizeTriangles(n, n, n, {0.5, 0.5, 0.5, 11.5, 11.5, 11.5, 11.5, 11.6, 11.5}, {0, 1, 2}, diag);
  for (int i = 0; i < n; ++i) EXPECT_TRUE(diag[(size_t(i) * n + size_t(i)) * n + size_t(i)]) << i;
  // Outside the grid: nothing.
  std::vector<uint8_t> none(size_t(n) * n * n, 0);
  EXPECT_EQ(voxelizeTriangles(n, n, n, {-5, -5, -5, -3, -5, -5, -5, -3, -5}, {0, 1, 2}, none), 0u);
}

TEST(Lightning3d, PolylinesAndTimelineIn3d) {
  Params p = volume(20, Method::kFast, 4);
  auto b = grow(p);
  ASSERT_TRUE(b.ok());
  const auto lines = polylines(b.value(), ShapeParams{});
  ASSERT_FALSE(lines.empty());
  bool offPlane = false;
  for (const auto& l : lines)
    for (const auto& v : l.vertices) {
      const Cell c = b.value().nodes[size_t(v.node)].cell;
      EXPECT_LE(std::fabs(v.z - (c.z + 0.5f)), 0.5f);
      offPlane = offPlane || c.z != p.start.z;
    }
  EXPECT_TRUE(offPlane) << "the bolt never left its start's z plane";
  const auto made = timeline(b.value(), lines, TimelineParams{});
  ASSERT_TRUE(made.ok()) << made.error().message;
  const Timeline& tl = made.value();
  for (size_t i = 0; i < lines.size(); ++i)
    for (size_t k = 1; k < tl.leader[i].size(); ++k) EXPECT_GE(tl.leader[i][k], tl.leader[i][k - 1]);
  EXPECT_GT(tl.duration, tl.connect);
}

TEST(Lightning3d, BoxCountingDimension) {
  // A straight line of voxels has D 1, a full plane 2, a full cube 3.
  std::vector<Cell> line, plane, cube;
  for (int i = 0; i < 64; ++i) line.push_back({i, 5, 7});
  for (int i = 0; i < 64; ++i)
    for (int j = 0; j < 64; ++j) plane.push_back({i, j, 9});
  for (int i = 0; i < 32; ++i)
    for (int j = 0; j < 32; ++j)
      for (int k = 0; k < 32; ++k) cube.push_back({i, j, k});
  EXPECT_NEAR(fractalDimension(line, 64, 64, 64), 1.0, 0.05);
  EXPECT_NEAR(fractalDimension(plane, 64, 64, 64), 2.0, 0.05);
  EXPECT_NEAR(fractalDimension(cube, 32, 32, 32), 3.0, 0.05);
  // A grown bolt lies between a line and a plane.
  auto b = grow(volume(64, Method::kFast, 2));
  ASSERT_TRUE(b.ok());
  std::vector<Cell> cells;
  for (const Node& n : b.value().nodes) cells.push_back(n.cell);
  const double D = fractalDimension(cells, 64, 64, 64);
  EXPECT_GT(D, 1.1);
  EXPECT_LT(D, 2.2);
}

}  // namespace
}  // namespace effects::lightning
