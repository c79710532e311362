// The error an answer states when it was not measured for this request: the figure the error
// report measured for the same method on its own scenes, with its limit of use and the report's
// row it comes from. The figures are read from the report's data embedded at build time
// (docs/error-vs-time/<section>.json; server/CMakeLists.txt), so there is no second copy to
// keep equal: regenerating a section changes what the next build states.
#pragma once

#include <cmath>
#include <string>

#include <effects/bubble.h>
#include <effects/lightning.h>
#include <effects/tangents.h>

namespace effectd {

struct ErrorEstimate {
  double value = NAN;
  double limit = INFINITY;  // the metric's limit of use, from the same data
  std::string section;      // the report's section (its data file)
  std::string row;          // the report's series there
  std::string setting;      // and its setting ("default", "tol 0.01", ...)
};

// The largest figure of `metric` among the section's rows of `series` (empty: of every series)
// whose setting starts with `settingPrefix`; NaN value when the data holds none (tests/report_test.cpp asks for every
// figure the server can state).
ErrorEstimate reported(const std::string& section, const std::string& series, const std::string& settingPrefix,
                       const std::string& metric);

// Mean total-variation distance per step from DBM's converged distribution (section lightning
// or lightning3d, metric tv): the method's default row for the nearest grid the report measures
// (64² or 128², the request's neighbourhood; 32³). DBM's capacitance solve is the converged
// solve itself; an iterative one (mgpcg, cg) takes the report's row at the nearest tolerance
// (64², 8-neighbourhood).
ErrorEstimate lightningErrorEstimate(const effects::lightning::Params& p);
// Mean angle from MikkTSpace's corner tangents, degrees (section tangents): the worse of the
// report's two meshes (a UV sphere and a mirrored bumpy torus). MikkTSpace itself: 0.
ErrorEstimate tangentsErrorEstimate(effects::tangents::Mode mode);
// Mean CIE76 Delta E*ab of the shading variant's frame against the CPU reference renderer
// (section render-bubble), on the report's one scene.
ErrorEstimate shadingErrorEstimate(const effects::bubble::Features& f);
// The fog pass's worst error in steps of 8-bit colour over the report's fogs (section render-fog),
// and the lightning pass's bound in pixels (section render-lightning: the limit is the bound).
ErrorEstimate fogPassErrorEstimate();
ErrorEstimate lightningPassErrorEstimate();

}  // namespace effectd
