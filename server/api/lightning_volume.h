// /v1/lightning's cells: where a 3-D grid lies in the world, and a grid's obstacles or target
// region from rects (2-D); boxes, spheres, a triangle mesh or a binary glTF (3-D, voxelised
// conservatively); rows or a bitmap (both).
#pragma once

#include <array>
#include <cstdint>
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

// "obstacles" or "targetRegion" as the body gives them: read and checked by the parse step,
// drawn into cells by the run step (a large grid's cells, or a mesh's voxelisation, are work
// done after admission). Spheres and triangles are in voxel units.
struct CellShapes {
  bool given = false;                     // any form present (even empty): the grid has cells
  std::vector<std::array<int, 4>> rects;  // 2-D: x, y, width, height
  std::vector<std::array<int, 6>> boxes;  // 3-D: x, y, z, width, height, depth
  struct Sphere {
    std::array<double, 3> center;
    double radius;
  };
  std::vector<Sphere> spheres;
  struct Row {
    int y, z;  // z: 3-D only
    std::vector<std::array<int, 2>> runs;  // x, length
  };
  std::vector<Row> rows;
  std::string bitmap;  // decoded: width*height(*depth) bits, row-major, most significant first
  struct Triangles {
    std::vector<double> positions;  // x, y, z per vertex
    std::vector<uint32_t> indices;  // three per triangle
  };
  std::vector<Triangles> meshes;  // "mesh", then "glb"'s
};

// Reads and checks the cells `o` gives on a w x h grid (d > 0: w x h x d); problems name the
// field under `at` ("/obstacles"). A mesh's voxelisation work is bounded here (413).
CellShapes parseCellShapes(const nlohmann::json& o, int w, int h, int d, const World& world, const Config& config,
                           const std::string& at);
// Their cells: w*h(*d) flags (x fastest, then y, then z), empty when none are given.
std::vector<uint8_t> drawCellShapes(const CellShapes& shapes, int w, int h, int d);

}  // namespace effectd
