// Bounds on one bolt's work (Limits) and the defaults a request that names nothing gets.
#include <algorithm>
#include <limits>
#include <string>

#include "effects/lightning.h"

namespace effects::lightning {

int defaultNeighbourhood(int depth) { return depth ? 26 : 8; }

std::optional<Error> checkLimits(const Params& p, const Limits& limits) {
  const auto knob = [](std::string_view k) { return k.empty() ? std::string() : " (" + std::string(k) + ")"; };
  // Sides as large as int allows: saturate rather than wrap (callers may not have validated).
  size_t cells = 0;
  if (__builtin_mul_overflow(size_t(std::max(p.width, 0)), size_t(std::max(p.height, 0)), &cells) ||
      __builtin_mul_overflow(cells, size_t(std::max(p.depth, 1)), &cells))
    cells = std::numeric_limits<size_t>::max();
  if (cells > limits.maxGridCells)
    return overLimit("/grid", "grid of " + std::to_string(cells) + " cells exceeds the limit of " +
                                  std::to_string(limits.maxGridCells) + knob(limits.gridKnob));
  const size_t solver = p.depth ? limits.maxSolverVolumeCells : limits.maxSolverGridCells;
  if (p.method != Method::kFast && cells > solver)
    return overLimit("/grid", "grid of " + std::to_string(cells) + " cells exceeds the limit of " +
                                  std::to_string(solver) + " for method " + toString(p.method) +
                                  knob(p.depth ? limits.solverVolumeKnob : limits.solverGridKnob) +
                                  "; the fast method takes up to " + std::to_string(limits.maxGridCells));
  return std::nullopt;
}

}  // namespace effects::lightning
