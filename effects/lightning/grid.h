// Private to effects/lightning: the obstacle grid, its boundary map, A* and line of sight.
#pragma once

#include <atomic>
#include <cstdlib>
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
constexpr int kDx4[4] = {0, -1, 1, 0};
constexpr int kDy4[4] = {-1, 0, 0, 1};

// The neighbour offsets of a 4- or 8-neighbourhood (Params::neighbourhood).
struct Stencil {
  const int* dx;
  const int* dy;
  int size;
};
inline Stencil stencil(int neighbourhood) {
  return neighbourhood == 4 ? Stencil{kDx4, kDy4, 4} : Stencil{kDx, kDy, 8};
}
// a and b are the same cell or neighbours in the neighbourhood.
inline bool touching(Cell a, Cell b, int neighbourhood) {
  const int dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y);
  return neighbourhood == 4 ? dx + dy <= 1 : dx <= 1 && dy <= 1;
}

// Seed 002 eqn 4: potential of the negative charges on the grid border (a ring of cells just
// outside the grid) and on obstacle cells, sum of 1/r. A pyramid of charge counts and
// centroids answers a query in O(log n) blocks (Barnes-Hut), so 1024^2 grids with 20 %
// obstacles cost milliseconds; the pyramid depends only on the grid and obstacles and is
// cached per (size, obstacle set) within 64 MB. Memory: a 4-bit charge mask per 2x2 cells
// (cells and 2x2 blocks are derived from it on the fly) and stored floats from 4x4 blocks up,
// about 1 byte per cell (17 MB at 4096^2); the cache keeps the obstacle grid as its key.
class BoundaryMap {
 public:
  BoundaryMap(int width, int height, const std::vector<uint8_t>& obstacles);
  // Thread-safe; on grids up to kMemoCells the value of each cell is kept once computed, so
  // every request on a cached map shares the work (stores are of the same value: races are
  // benign, the atomics make them defined).
  double potential(int x, int y) const;
  static constexpr size_t kMemoCells = size_t(1) << 20;
  size_t bytes() const;

 private:
  struct Level {
    int w, h;                   // blocks per side
    std::vector<float> count;   // charges in the block
    std::vector<float> cx, cy;  // their centroid (domain coordinates)
  };
  // Charges of 2x2 cells as a 4-bit mask per block, bit (dx & 1) + 2 (dy & 1).
  uint8_t quad(int qx, int qy) const { return quads_[size_t(qy) * size_t(qw_) + size_t(qx)]; }
  bool charge(int dx, int dy) const { return (quad(dx / 2, dy / 2) >> ((dx & 1) + 2 * (dy & 1))) & 1u; }
  double visit(int level, int bx, int by, double px, double py) const;
  int dw_, dh_;  // domain (grid + ring) size
  int qw_, qh_;  // 2x2 blocks per side
  std::vector<uint8_t> quads_;
  std::vector<Level> levels_;  // levels_[k - 2]: blocks of 2^k x 2^k cells, k >= 2
  size_t memoCells_ = 0;
  std::unique_ptr<std::atomic<float>[]> memo_;  // 0 = not computed yet (a potential is > 0)
};

std::shared_ptr<const BoundaryMap> cachedBoundaryMap(int width, int height, const std::vector<uint8_t>& obstacles,
                                                     bool* hit);

bool lineOfSight(const Grid& g, Cell a, Cell b);
// Turning points of a path (direction changes), ending with its last cell.
std::vector<Cell> turningPoints(const std::vector<Cell>& path);

}  // namespace effects::lightning::detail
