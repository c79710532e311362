// Prints the lightning calibration's current table (effects/lightning/calibration.cpp) as
// Markdown, for scripts/calibration-table.py to place in docs/lightning-calibration.md.
#include <cstdio>

#include "lightning/calibration.h"

int main() {
  std::fputs(effects::lightning::calibrationMarkdown().c_str(), stdout);
  return 0;
}
