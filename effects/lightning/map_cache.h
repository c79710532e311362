// Private to effects/lightning: the cache of per-grid maps and tables (boundary maps, the
// capacitance solver's tables of G), keyed by the grid's size and its obstacles.
#pragma once

#include <cstddef>
#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

namespace effects::lightning::detail {

// The cache's key for an obstacle grid: one bit a cell (an obstacle is any non-zero byte),
// empty where no cell is blocked.
std::vector<uint64_t> obstacleBits(const std::vector<uint8_t>& obstacles);

// Maps and tables of recent keys (size, obstacle bits), 2-D (depth 0), 3-D and others (the
// caller's choice of depth), kept within 64 MB in all, least recently used first out:
// build() makes a missing one; *hit says whether it was there.
std::shared_ptr<const void> cachedMap(int width, int height, int depth, const std::vector<uint64_t>& obstacleKey,
                                      bool* hit, const std::function<std::shared_ptr<const void>()>& build,
                                      size_t (*mapBytes)(const void*));

}  // namespace effects::lightning::detail
