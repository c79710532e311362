// /v1/lightning on a 3-D grid: where the grid lies in the world, and its obstacles from boxes,
// spheres, a bitmap, a triangle mesh or a binary glTF (voxelised conservatively).
#pragma once

#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "contract/config.h"

namespace effectd {

// "world": voxel corner (x, y, z) lies at origin + cellSize * (x, -y, -z).
struct World {
  bool given = false;
  std::array<double, 3> origin{0, 0, 0};
  double cellSize = 1;
  // World point -> voxel coordinates (the identity without "world").
  std::array<double, 3> toVoxels(const std::array<double, 3>& p) const {
    if (!given) return p;
    return {(p[0] - origin[0]) / cellSize, -(p[1] - origin[1]) / cellSize, -(p[2] - origin[2]) / cellSize};
  }
  std::array<double, 3> toWorld(double x, double y, double z) const {
    if (!given) return {x, y, z};
    return {origin[0] + cellSize * x, origin[1] - cellSize * y, origin[2] - cellSize * z};
  }
};

// The request's "world" (schema-valid); absent: not given.
World parseWorld(const nlohmann::json& body);

// The obstacle voxels of a w x h x d grid (empty when none are given); problems name the field
// under `at` ("/obstacles").
std::vector<uint8_t> parseVolumeObstacles(const nlohmann::json& o, int w, int h, int d, const World& world,
                                          const Config& config, const std::string& at);

}  // namespace effectd
