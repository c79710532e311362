// The fast method's calibration against DBM, as data: the laws below the table, the table of
// settings per grid side and eta with its feet, and the rule that blends between them. This file
// (calibration.cpp) is the one place they are written; docs/lightning-calibration.md's
// "Current table" is calibrationMarkdown()'s output (scripts/calibration-table.py), and
// docs/lightning-calibration-history.md says how each number was measured.
#pragma once

#include <string>

namespace effects::lightning {

// The current calibration in Markdown: the laws, the four tables with their feet, the blending
// rule, and the settings it gives at a grid of sides and etas.
std::string calibrationMarkdown();

}  // namespace effects::lightning
