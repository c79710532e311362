// Private to effects/lightning: the draw of seed 002 eqn 2, index i with probability
// Phi_i^eta / sum Phi^eta, by one uniform U against the running sum of the weights in slot
// order; and the same draw decided from bounds on the weights, for a method that knows most
// of them only from above (dbm.cpp's direct steps: docs/effects.md section 1.3, the bounded
// draw).
#pragma once

#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstddef>
#include <vector>

#include "effects/common.h"

namespace effects::lightning::detail {

// log Phi of a potential, Phi below DBL_MIN (0 included) read as DBL_MIN.
inline double logPotential(double phi) { return std::log(std::max(phi, DBL_MIN)); }
// Phi^eta relative to the largest Phi, from their logs: what every draw weighs a candidate by.
inline double relativeWeight(double logPhi, double eta, double logTop) { return std::exp(eta * (logPhi - logTop)); }

// Unnormalised p_i = Phi_i^eta from log Phi, scaled by the largest so that nothing
// overflows; eta = 0 or all Phi = 0 gives uniform weights (0^0 = 1). Returns the sum.
double candidateWeights(const std::vector<double>& logPhi, double eta, std::vector<double>& w);
// The index whose slot holds u * sum w: the smallest i with w_0 + ... + w_i > u * sum w.
size_t sampleAt(const std::vector<double>& logPhi, double eta, double u, std::vector<double>& w);
// sampleAt with u = rng.uniform().
size_t sample(const std::vector<double>& logPhi, double eta, Rng& rng, std::vector<double>& w);

// What sampleAt would pick from weights known only to lie in [lo_i, hi_i] (lo_i = hi_i where
// a weight is known exactly), or kUndecided where the bounds leave it open: the pick i must
// satisfy S_i <= u W < S_i + w_i (S_i the sum of the weights before slot i, W the sum of all)
// for every choice of weights within the bounds, with room of kDrawMargin W on both sides, so
// that the rounding of sampleAt's own sums cannot pick another slot. The pick is always a
// slot whose weight is known exactly (a slot with lo < hi cannot be certain).
constexpr size_t kUndecided = size_t(-1);
constexpr double kDrawMargin = 1e-9;
size_t decidedDraw(const std::vector<double>& lo, const std::vector<double>& hi, double u);

}  // namespace effects::lightning::detail
