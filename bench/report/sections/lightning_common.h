// What the lightning sections share: the layouts, the settings a client can send for a grid
// (each with its request fields), a bolt's fractal dimension, and the timing of bolts over seeds.
#pragma once

#include <effects/lightning.h>

#include "../report.h"

namespace report {

namespace lt = effects::lightning;

struct LightningSetting {
  std::string series, setting;
  json request;  // the fields a client sends for it
  lt::Params params;
};

// The start-to-target layout of an n^2 grid or, with `volume`, an n^3 one, as the server
// calibrates it.
lt::Params layoutOf(int n, bool volume);
// The settings of one grid and neighbourhood: the calibrated default, the paper's constants
// (variant paper) and the lifetimes through them, eqn 8's base, charges (2-D), DBM's solvers
// and tolerances.
std::vector<LightningSetting> lightningSettings(bool quick, int n, int hood, bool volume);
// The request fields of a grid: {"grid": {...}, "neighbourhood": hood}.
json gridRequest(int n, int hood, bool volume);
double dimensionOf(const lt::Bolt& b, int n);
// The time of `p` over seeds 1..seeds: each seed's bolt grown again, its own elapsed time. Each
// timing process grows every seed while they fit in kBoltTimingMs at `boltMs` a bolt (the
// median the measurement saw); slower bolts get k seeds a process, process r from seed r k + 1,
// so that the processes together cover the seeds rather than time the first one thrice.
constexpr double kBoltTimingMs = 300;
size_t timeBolts(Run& run, const std::string& name, lt::Params p, int seeds, double boltMs);

// The tv and fd metrics (the lightning and lightning3d sections).
Metric tvMetric();
Metric fdMetric();
// Both sections' rows: every setting over seeds, D against DBM's and, up to 128^2, the mean
// per-step total-variation distance.
void lightningRows(Run& run, int n, int hood, bool volume);
// Both sections' conclusion.
std::string lightningConclusion(const Run& run);

}  // namespace report
