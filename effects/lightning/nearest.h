// Private to effects/lightning: the distance from a cell to the nearest cell of a set (a target
// region), by a k-d tree over the set's surface cells. Seed 002 eqn 5's P is the distance to
// the positive charge; when the charge is a region (the ground) it is the distance to the
// region's nearest cell.
#pragma once

#include <cstdint>
#include <vector>

#include "effects/lightning.h"

namespace effects::lightning::detail {

class NearestCells {
 public:
  NearestCells() = default;
  // flags: width*height*depth (x fastest), nonzero = in the set. Only cells with a face
  // neighbour outside the set (inside the grid) are kept: from any cell outside the set the
  // nearest cell of the set is one of them (a step from an inner cell towards the query
  // would be nearer still).
  NearestCells(int width, int height, int depth, const std::vector<uint8_t>& flags);
  bool empty() const { return cells_.empty(); }
  size_t size() const { return cells_.size(); }
  // Euclidean distance between c's centre and the nearest kept cell's (0 if c is one).
  double distance(Cell c) const;

 private:
  void build(size_t lo, size_t hi);
  void search(size_t lo, size_t hi, Cell c, int64_t& best) const;
  std::vector<Cell> cells_;    // an implicit k-d tree: each range's middle cell splits it
  std::vector<uint8_t> axis_;  // the split axis at each range's middle (0 x, 1 y, 2 z)
};

}  // namespace effects::lightning::detail
