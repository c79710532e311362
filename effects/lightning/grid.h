// Private to effects/lightning: the obstacle grid, its boundary map, A* and line of sight.
#pragma once

#include <memory>
#include <vector>

#include "effects/lightning.h"

namespace effects::lightning::detail {

struct Grid {
  int width, height;
  const std::vector<uint8_t>* obstacles;  // may be empty
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width && y < height; }
  bool blocked(int x, int y) const {
    return !obstacles->empty() && (*obstacles)[size_t(y) * size_t(width) + size_t(x)] != 0;
  }
  size_t index(Cell c) const { return size_t(c.y) * size_t(width) + size_t(c.x); }
};

constexpr int kDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};

// Seed 002 eqn 4: potential of the negative charges on the grid border (a ring of cells just
// outside the grid) and on obstacle cells, sum of 1/r. A pyramid of charge counts and
// centroids answers a query in O(log n) blocks (Barnes-Hut), so 1024^2 grids with 20 %
// obstacles cost milliseconds; the pyramid depends only on the grid and obstacles and is
// cached per (size, obstacle set). Memory: one bit per cell for the charges (which is also
// the cache key), blocks of 2x2 cells derived from it on the fly, stored floats from 4x4
// blocks up: about 1.1 bytes per cell (19 MB at 4096^2).
class BoundaryMap {
 public:
  BoundaryMap(int width, int height, const std::vector<uint8_t>& obstacles);
  double potential(int x, int y) const;
  bool sameGrid(int width, int height, const std::vector<uint8_t>& obstacles) const;
  size_t bytes() const;

 private:
  struct Level {
    int w, h;                     // blocks per side
    std::vector<float> count;     // charges in the block
    std::vector<float> cx, cy;    // their centroid (domain coordinates)
  };
  bool charge(int dx, int dy) const {  // domain coordinates (grid + 1); the ring is the rim
    size_t i = size_t(dy) * size_t(dw_) + size_t(dx);
    return (bits_[i / 64] >> (i % 64)) & 1u;
  }
  double visit(int level, int bx, int by, double px, double py) const;
  int width_, height_, dw_, dh_;  // grid and domain (grid + ring) sizes
  std::vector<uint64_t> bits_;    // charge per domain cell
  std::vector<Level> levels_;     // levels_[k - 2]: blocks of 2^k x 2^k cells, k >= 2
};

std::shared_ptr<const BoundaryMap> cachedBoundaryMap(int width, int height, const std::vector<uint8_t>& obstacles,
                                                     bool* hit);

bool lineOfSight(const Grid& g, Cell a, Cell b);
// Turning points of a path (direction changes), ending with its last cell.
std::vector<Cell> turningPoints(const std::vector<Cell>& path);

}  // namespace effects::lightning::detail
