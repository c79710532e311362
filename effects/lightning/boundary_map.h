// Private to effects/lightning: seed 002's eqn 4, B, the potential of the border's and the
// obstacles' charges, as Barnes-Hut maps (2-D: boundary_map.cpp; 3-D: volume.cpp), cached per
// grid (map_cache.h).
#pragma once

#include <atomic>
#include <cstdlib>
#include <memory>
#include <vector>

#include "grid.h"

namespace effects::lightning::detail {

// A boundary map's memo: a float per cell, 0 until stored, shared by the concurrent requests
// on a cached map. Pages of kPage cells are made on a cell's first store (one compare-and-swap
// on the page's pointer; the loser frees its page), so a map costs only the pages its bolts
// asked about, and making a map clears no per-cell array. Values are read and written through
// std::atomic_ref: stores are of the same value, so races are benign and the atomics make
// them defined.
class SharedMemo {
 public:
  static constexpr size_t kPageBits = 10, kPage = size_t(1) << kPageBits;
  explicit SharedMemo(size_t cells = 0) : pages_((cells + kPage - 1) >> kPageBits), dir_(new float*[pages_]()) {}
  ~SharedMemo() {
    for (size_t p = 0; p < pages_; ++p) std::free(std::atomic_ref<float*>(dir_[p]).load(std::memory_order_relaxed));
  }
  SharedMemo(const SharedMemo&) = delete;
  SharedMemo& operator=(const SharedMemo&) = delete;
  float get(size_t i) const {
    float* page = std::atomic_ref<float*>(dir_[i >> kPageBits]).load(std::memory_order_acquire);
    return page ? std::atomic_ref<float>(page[i & (kPage - 1)]).load(std::memory_order_relaxed) : 0.0f;
  }
  void put(size_t i, float v) const {
    std::atomic_ref<float*> slot(dir_[i >> kPageBits]);
    float* page = slot.load(std::memory_order_acquire);
    if (!page) {
      float* made = static_cast<float*>(std::calloc(kPage, sizeof(float)));
      if (!made) return;  // the value is only not kept
      if (slot.compare_exchange_strong(page, made, std::memory_order_acq_rel))
        page = made;
      else
        std::free(made);  // another request made it: page now holds theirs
    }
    std::atomic_ref<float>(page[i & (kPage - 1)]).store(v, std::memory_order_relaxed);
  }
  size_t bytes() const { return pages_ * (kPage * sizeof(float) + sizeof(float*)); }  // all pages made

 private:
  size_t pages_;
  std::unique_ptr<float*[]> dir_;  // a page's pointer, null until made
};

// Seed 002 eqn 4: potential of the negative charges on the grid border (a ring of cells just
// outside the grid) and on obstacle cells, sum of 1/r. A scene's B adds two maps
// (SceneBoundary): the border's, which depends on the grid size only, and its obstacles'.
// A map is a pyramid of charge counts and centroids that answers a query in O(log n) blocks
// (Barnes-Hut), so 1024^2 grids with 20 % obstacles cost milliseconds. Memory: a 4-bit
// charge mask per 2x2 cells (cells and 2x2 blocks are derived from it on the fly) and stored
// floats from 4x4 blocks up, about 1 byte per cell (17 MB at 4096^2).
class BoundaryMap {
 public:
  // obstacles == nullptr: the border's charges; otherwise the obstacle cells' alone.
  BoundaryMap(int width, int height, const std::vector<uint8_t>* obstacles);
  // Thread-safe; on grids up to kMemoCells the value of each cell is kept once computed, so
  // every request on a cached map shares the work (stores are of the same value: races are
  // benign, the atomics make them defined).
  double potential(Cell c) const;
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
  SharedMemo memo_;  // 0 = not computed yet (a potential is > 0)
};

// Seed 002 eqn 4 in 3-D: sum of 1/r over the shell of voxels around the grid and the obstacle
// voxels, as in 2-D two maps that add: the shell's and the obstacles'. An octree of charge
// counts and centroids (blocks of 4^3 voxels and up) answers a query in O(log n) blocks with
// the opening angle of the 2-D map; blocks nearer than two of their sides are summed voxel by
// voxel. Memory: 24 bytes per 4^3 block of the padded grid (a charge bit per voxel, count and
// centroid; about 0.4 bytes per voxel), and on grids up to kMemoVoxels the memo's pages (as
// BoundaryMap's: each voxel's value kept once computed, shared by every request on a cached
// map; the value is then a float's whether it came from the memo or not).
class VolumeBoundary {
 public:
  // obstacles == nullptr: the shell's charges; otherwise the obstacle voxels' alone.
  VolumeBoundary(int width, int height, int depth, const std::vector<uint8_t>* obstacles);
  double potential(Cell c) const;  // thread-safe
  static constexpr size_t kMemoVoxels = size_t(1) << 21;  // 128^3
  size_t bytes() const;

 private:
  struct Level {
    int w, h, d;              // blocks per side
    std::vector<float> count, cx, cy, cz;
  };
  double visit(int level, int bx, int by, int bz, double px, double py, double pz) const;
  int dw_, dh_, dd_;             // domain (grid + shell) size
  std::vector<uint64_t> leafCharges_;  // per 4^3 block of levels_[0]: bit (dz * 4 + dy) * 4 + dx
  std::vector<Level> levels_;    // levels_[k]: blocks of 4 * 2^k voxels a side
  int w_, h_;                    // grid width and height (the memo's rows)
  size_t memoVoxels_ = 0;
  SharedMemo memo_;  // as BoundaryMap's
};

// A scene's B: the border's map, cached per grid size and shared by every scene of that size,
// plus the obstacles' map, cached per obstacle set (none where nothing is blocked). A scene
// with new obstacles builds only their map; the border's, which every query visits, answers
// from its memo.
template <class Map>
struct SceneBoundary {
  std::shared_ptr<const Map> border, obstacles;
  bool cached = true;  // neither map had to be built
  double potential(Cell c) const { return border->potential(c) + (obstacles ? obstacles->potential(c) : 0.0); }
};
SceneBoundary<BoundaryMap> cachedBoundary(int width, int height, const std::vector<uint8_t>& obstacles);
SceneBoundary<VolumeBoundary> cachedBoundary(int width, int height, int depth, const std::vector<uint8_t>& obstacles);

}  // namespace effects::lightning::detail
