// The error an answer states when it was not measured for this request: the figure the error
// report (docs/error-vs-time.md) measured for the same method on its own scenes, with the
// report's row it comes from. One place for every such figure; tests/report_test.cpp holds each
// to the committed report (docs/error-vs-time.json), so that a regenerated report with other
// numbers fails there rather than leaving these behind.
#pragma once

#include <string>

#include <effects/bubble.h>
#include <effects/lightning.h>
#include <effects/tangents.h>

namespace effectd {

struct ErrorEstimate {
  double value = 0;
  std::string section;  // the report's section (its JSON key)
  std::string row;      // the report's series there
  std::string setting;  // and its setting ("default", "tol 0.01", ...)
};

// Mean total-variation distance per step from DBM's converged distribution (section
// lightning-tv or lightning3d-tv): the method's default row for the nearest grid the report
// measures (64² or 128², the request's neighbourhood; 32³). DBM's capacitance solve is the
// converged solve itself; an iterative one (mgpcg, cg) takes the report's row at the nearest
// tolerance (64², 8-neighbourhood).
ErrorEstimate lightningErrorEstimate(const effects::lightning::Params& p);
// Mean angle from MikkTSpace's corner tangents, degrees (section tangents): the worse of the
// report's two meshes (a UV sphere and a mirrored bumpy torus). MikkTSpace itself: 0.
ErrorEstimate tangentsErrorEstimate(effects::tangents::Mode mode);
// Mean CIE76 Delta E*ab of the shading variant's frame against the CPU reference renderer
// (section render-bubble), on the report's one scene.
ErrorEstimate shadingErrorEstimate(const effects::bubble::Features& f);

}  // namespace effectd
