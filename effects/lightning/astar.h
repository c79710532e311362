// Private to effects/lightning: the guide of seed 002 section 3.2: an A* path around the
// obstacles (effects/lightning.h: astar, astarToRegion), its turning points, and the line of
// sight that moves growth on to the next one.
#pragma once

#include <vector>

#include "grid.h"
#include "hooks.h"

namespace effects::lightning::detail {

bool lineOfSight(const Grid& g, Cell a, Cell b);
// Turning points of a path (direction changes), ending with its last cell.
std::vector<Cell> turningPoints(const std::vector<Cell>& path);

}  // namespace effects::lightning::detail
