// The draw of seed 002 eqn 2, exact and from bounds (draw.h).
#include "draw.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace effects::lightning::detail {

double candidateWeights(const std::vector<double>& logPhi, double eta, std::vector<double>& w) {
  constexpr double kNegInf = -std::numeric_limits<double>::infinity();
  w.resize(logPhi.size());
  double top = kNegInf;
  for (double l : logPhi) top = std::max(top, l);
  double sum = 0;
  for (size_t i = 0; i < logPhi.size(); ++i) {
    w[i] = (eta == 0.0 || top == kNegInf) ? 1.0 : relativeWeight(logPhi[i], eta, top);
    sum += w[i];
  }
  return sum;
}

size_t sampleAt(const std::vector<double>& logPhi, double eta, double u, std::vector<double>& w) {
  u *= candidateWeights(logPhi, eta, w);
  for (size_t i = 0; i < w.size(); ++i) {
    u -= w[i];
    if (u < 0) return i;
  }
  size_t last = w.size() - 1;
  while (last > 0 && w[last] == 0) --last;
  return last;
}

size_t sample(const std::vector<double>& logPhi, double eta, Rng& rng, std::vector<double>& w) {
  return sampleAt(logPhi, eta, rng.uniform(), w);
}

size_t decidedDraw(const std::vector<double>& lo, const std::vector<double>& hi, double u) {
  // S_k - u W = (1 - u) S_k - u R_k (R_k = W - S_k) rises with k; within the bounds it lies in
  // [(1 - u) Slo_k - u Rhi_k, (1 - u) Shi_k - u Rlo_k]. The pick is the first slot i after
  // which it is certainly above 0, provided it was certainly below 0 before i.
  double wLo = 0, wHi = 0;
  for (size_t i = 0; i < lo.size(); ++i) wLo += lo[i], wHi += hi[i];
  const double margin = kDrawMargin * wHi;
  if (!(wLo > 0)) return kUndecided;
  double sLo = 0, sHi = 0;
  for (size_t i = 0; i < lo.size(); ++i) {
    const double nextLo = sLo + lo[i], nextHi = sHi + hi[i];
    if ((1 - u) * nextLo - u * (wHi - nextHi) > margin)
      return (1 - u) * sHi - u * (wLo - sLo) < -margin ? i : kUndecided;
    sLo = nextLo, sHi = nextHi;
  }
  return kUndecided;
}

}  // namespace effects::lightning::detail
