// Private to effects/lightning: the obstacle grid (2-D or 3-D), the per-request cell maps, the
// neighbourhoods. The boundary maps are boundary_map.h's, the guide astar.h's.
#pragma once

#include <atomic>
#include <cstdlib>
#include <functional>
#include <memory>
#include <new>
#include <vector>

#include "effects/lightning.h"

namespace effects::lightning::detail {

// A value per cell, zero until set, for the bookkeeping of one request (bolt and candidate
// cells, A*'s search). A bolt touches a sliver of a large grid, and clearing (or faulting in)
// a flat array of a 4096^2 or 128^3 grid cost more than growing the bolt. So the cells come
// in pages of kPage consecutive cells, each made (zeroed) when a cell of it is first set;
// reads of a page never set are zero. Neighbours along a row share a page, so a search that
// floods a region reads memory as a flat array would. Memory: the pages touched, and a
// pointer per page of the grid.
template <class T>
class CellMap {
 public:
  static constexpr size_t kPageBits = 8, kPage = size_t(1) << kPageBits;
  explicit CellMap(size_t cells = 0) : dir_((cells + kPage - 1) >> kPageBits) {}
  T get(size_t i) const {
    const T* p = dir_[i >> kPageBits];
    return p ? p[i & (kPage - 1)] : T{};
  }
  T& at(size_t i) {  // the cell's value, to set
    T*& p = dir_[i >> kPageBits];
    if (!p) p = newPage();
    return p[i & (kPage - 1)];
  }

 private:
  static constexpr size_t kChunkPages = 16;  // pages come from chunks of this many
  T* newPage() {
    if (used_ == kChunkPages || chunks_.empty()) {
      chunks_.push_back(std::make_unique<T[]>(kChunkPages * kPage));  // value-initialised: zero
      used_ = 0;
    }
    return chunks_.back().get() + kPage * used_++;
  }
  std::vector<T*> dir_;
  std::vector<std::unique_ptr<T[]>> chunks_;
  size_t used_ = 0;  // pages handed out from the last chunk
};

// A per-cell index, -1 where unset (stored + 1).
class CellIndex {
 public:
  explicit CellIndex(size_t n = 0) : v_(n) {}
  int32_t get(size_t i) const { return v_.get(i) - 1; }
  void set(size_t i, int32_t value) { v_.at(i) = value + 1; }

 private:
  CellMap<int32_t> v_;
};

struct Grid {
  int width, height;
  const std::vector<uint8_t>* obstacles;  // may be empty
  int depth = 1;                          // 1 for a 2-D grid
  bool inside(int x, int y, int z = 0) const {
    return x >= 0 && y >= 0 && z >= 0 && x < width && y < height && z < depth;
  }
  size_t index(int x, int y, int z = 0) const {
    return (size_t(z) * size_t(height) + size_t(y)) * size_t(width) + size_t(x);
  }
  size_t index(Cell c) const { return index(c.x, c.y, c.z); }
  bool blocked(int x, int y, int z = 0) const { return !obstacles->empty() && (*obstacles)[index(x, y, z)] != 0; }
  size_t cells() const { return size_t(width) * size_t(height) * size_t(depth); }
  Cell cellAt(size_t i) const {
    const size_t w = size_t(width), h = size_t(height);
    return {int(i % w), int(i / w % h), int(i / (w * h))};
  }
};

constexpr int kDx[8] = {-1, 0, 1, -1, 1, -1, 0, 1};
constexpr int kDy[8] = {-1, -1, -1, 0, 0, 1, 1, 1};
constexpr int kDx4[4] = {0, -1, 1, 0};
constexpr int kDy4[4] = {-1, 0, 0, 1};
constexpr int kDz0[26] = {};
// 3-D: the 26 offsets in z, y, x order, and the 6 faces.
constexpr int kDx26[26] = {-1, 0, 1, -1, 0, 1, -1, 0, 1, -1, 0, 1, -1, 1, -1, 0, 1, -1, 0, 1, -1, 0, 1, -1, 0, 1};
constexpr int kDy26[26] = {-1, -1, -1, 0, 0, 0, 1, 1, 1, -1, -1, -1, 0, 0, 1, 1, 1, -1, -1, -1, 0, 0, 0, 1, 1, 1};
constexpr int kDz26[26] = {-1, -1, -1, -1, -1, -1, -1, -1, -1, 0, 0, 0, 0, 0, 0, 0, 0, 1, 1, 1, 1, 1, 1, 1, 1, 1};
constexpr int kDx6[6] = {0, 0, -1, 1, 0, 0};
constexpr int kDy6[6] = {0, -1, 0, 0, 1, 0};
constexpr int kDz6[6] = {-1, 0, 0, 0, 0, 1};

// The neighbour offsets of a 4- or 8-neighbourhood, or in 3-D a 6- or 26-neighbourhood
// (Params::neighbourhood; dz is all 0 in 2-D).
struct Stencil {
  const int* dx;
  const int* dy;
  int size;
  const int* dz = kDz0;
};
inline Stencil stencil(int neighbourhood) {
  switch (neighbourhood) {
    case 4: return {kDx4, kDy4, 4};
    case 6: return {kDx6, kDy6, 6, kDz6};
    case 26: return {kDx26, kDy26, 26, kDz26};
    default: return {kDx, kDy, 8};
  }
}
// a and b are the same cell or neighbours in the neighbourhood.
inline bool touching(Cell a, Cell b, int neighbourhood) {
  const int dx = std::abs(a.x - b.x), dy = std::abs(a.y - b.y), dz = std::abs(a.z - b.z);
  return neighbourhood == 4 || neighbourhood == 6 ? dx + dy + dz <= 1 : dx <= 1 && dy <= 1 && dz <= 1;
}

}  // namespace effects::lightning::detail
