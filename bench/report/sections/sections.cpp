// Every section of the error report, in report order.
#include "sections.h"

namespace report {

std::vector<Section> allSections() {
  return {lightningSection(),   lightning3dSection(), lightningShapeSection(), fogTablesSection(),
          fogHeightMarchSection(), fogConventionsSection(), tangentsSection(), thinFilmSection(),
          glowSection(),        renderBubbleSection(), renderFogSection(),     renderLightningSection()};
}

}  // namespace report
