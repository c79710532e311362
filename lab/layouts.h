// The geometries games use, as lightning layouts for the shape comparisons (issue 49):
// lab/lightning_shape.cpp and lab/lightning_phi_fit.cpp. At size s:
//   open      the calibration's own: start top-centre, target bottom-centre, s x s
//   off-axis  start at s/4 on the top row, target at 3s/4 on the bottom row
//   ground    start top-centre, every bottom cell a target (a target region)
//   wall      examples/04-storm-over-water.json's bolt scaled to s: an off-axis strike over a
//             wall that the A* guide leads around
//   wide      the ground on a 2s x s grid
//   3d        s^3 voxels (26 neighbours), start at the top face's centre, the bottom layer a
//             target region
#pragma once

#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <string>

#include <effects/lightning.h>

namespace bench::shape {

// The layout of a geometry (above) at size s, before method, eta and seed.
inline effects::lightning::Params layout(const std::string& geometry, int s) {
  effects::lightning::Params p;
  p.width = p.height = s;
  p.start = {s / 2, 1};
  p.targets = {{s / 2, s - 2}};
  auto ground = [&] {
    p.targets.clear();
    p.targetRegion.assign(size_t(p.width) * size_t(p.height) * size_t(std::max(p.depth, 1)), 0);
    for (int z = 0; z < std::max(p.depth, 1); ++z)
      for (int x = 0; x < p.width; ++x)
        p.targetRegion[(size_t(z) * size_t(p.height) + size_t(p.height - 1)) * size_t(p.width) + size_t(x)] = 1;
  };
  if (geometry == "off-axis") {
    p.start = {s / 4, 1};
    p.targets = {{3 * s / 4, s - 2}};
  } else if (geometry == "ground") {
    ground();
  } else if (geometry == "wide") {
    p.width = 2 * s;
    p.start = {s, 1};
    ground();
  } else if (geometry == "3d") {
    p.depth = s;
    p.neighbourhood = 26;
    p.start = {s / 2, 1, s / 2};
    ground();
  } else if (geometry == "wall") {  // example 04 at 96: start (20, 0), target (70, 95), wall [30, 40, 36, 6]
    auto at = [s](int v) { return v * s / 96; };
    p.start = {at(20), 0};
    p.targets = {{at(70), s - 1}};
    p.obstacles.assign(size_t(s) * size_t(s), 0);
    for (int y = at(40); y < at(46); ++y)
      for (int x = at(30); x < at(66); ++x) p.obstacles[size_t(y) * size_t(s) + size_t(x)] = 1;
  } else if (geometry != "open") {
    std::fprintf(stderr, "unknown geometry %s (open, off-axis, ground, wall, wide, 3d)\n", geometry.c_str());
    std::exit(2);
  }
  return p;
}

}  // namespace bench::shape
