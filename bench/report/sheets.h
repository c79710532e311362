// Sheets of bolts side by side, the lightning-shape section's pictures: DBM's and the fast
// method's bolts on the same seeds, one sheet per layout (3-D: seen along z), drawn by gnuplot.
#pragma once

#include <array>
#include <filesystem>
#include <string>
#include <vector>

#include <effects/lightning.h>

namespace report {

struct Sheet {
  std::string id, caption;
  int width = 0, height = 0;        // the grid's x and y extent
  std::vector<std::string> titles;  // per panel; panels fill rows of `columns`
  // Per panel, the tree's edges (x0, y0, x1, y1 at cell centres): branches, then main channel.
  std::vector<std::vector<std::array<float, 4>>> branches, main;
  std::vector<std::array<int, 4>> obstacles;  // x, y, width, height: runs of obstacle cells (2-D)
  int columns = 4;
};

// A bolt's edges as one more panel: each node to its parent, at cell centres.
void addPanel(Sheet& sheet, const effects::lightning::Bolt& bolt, const std::string& title);
// The obstacles of a 2-D layout, as runs along rows.
void addObstacles(Sheet& sheet, const std::vector<uint8_t>& obstacles);
// The sheet as <dir>/<id>.png: white main channels and blue branches on black, y down. False
// when gnuplot failed.
bool drawSheet(const Sheet& sheet, const std::filesystem::path& dir);

}  // namespace report
