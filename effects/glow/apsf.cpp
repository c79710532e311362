// The atmospheric point spread function's series (glow.h): the reference every glow kernel is
// measured against.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "effects/glow.h"

namespace effects::glow {
namespace {

// ln(g_m / g_1) for m = 1, 2, ... until the rest of the series is below kSeriesTolerance of
// its value at theta = 0 (which is at least 2 g_1: every term there is 2 g_m > 0).
//   g_m / g_1 = e^(-beta_m T - (m - 1) ln T)   (beta_1 = 0 for every q, so g_1 = T^-2)
// The tail bound: beta_{k+1} - beta_k >= -1/(k (k+1)), so the ratio of consecutive terms is at
// most rho_k = e^(T / (k (k+1))) / T, falling in k; once rho_m < 1 the terms after m sum to at
// most r_m rho_m / (1 - rho_m), and |L_m| <= 1 doubles it.
struct Terms {
  std::vector<double> ratio;  // g_m / g_1, index m - 1
  double truncation = 0;      // the tail bound, relative to the value at theta = 0
};

Terms terms(double t, double q) {
  Terms out;
  const double lnT = std::log(t);
  constexpr int kMaxTerms = 1 << 20;
  for (int m = 1; m <= kMaxTerms; ++m) {
    const double beta = m == 1 ? 0.0 : (2.0 * m + 1) / m * -std::expm1(double(m - 1) * std::log(q));
    const double lr = -beta * t - double(m - 1) * lnT;
    out.ratio.push_back(std::exp(lr));
    const double rho = std::exp(t / (double(m) * (m + 1)) - lnT);
    if (rho < 1) {
      const double lnTail = lr + std::log(rho / (1 - rho));  // of sum over k > m of r_k, per unit |L|
      if (lnTail < std::log(kSeriesTolerance)) {             // 2 r tail / (2 r_1 = 2) at theta = 0
        out.truncation = std::exp(lnTail);
        break;
      }
    }
  }
  return out;
}

}  // namespace

std::optional<Error> validate(const Medium& m) {
  if (!(m.thickness >= 0) || !std::isfinite(m.thickness))
    return invalid("/opticalThickness", "must be finite and non-negative");
  if (!(m.forwardScattering >= 0 && m.forwardScattering <= 1))
    return invalid("/forwardScattering", "must be in [0, 1]");
  return std::nullopt;
}

double shapeThickness(const Medium& m) { return std::clamp(m.thickness, kMinSeriesThickness, kMaxThickness); }

Profile apsf(const Medium& medium, const std::vector<double>& angles) {
  const double t = shapeThickness(medium);
  // q = 0: q^(m-1) is 1 at m = 1 and 0 after (log(0) = -inf, expm1(-inf) = -1).
  const Terms series = terms(t, medium.forwardScattering);
  Profile p;
  p.angles = angles;
  p.terms = int(series.ratio.size());
  p.truncation = series.truncation;
  p.values.reserve(angles.size());
  for (double angle : angles) {
    const double mu = std::cos(angle);
    double previous = 1, current = mu, sum = 0;  // L_{m-1}, L_m at m = 1
    for (size_t i = 0; i < series.ratio.size(); ++i) {
      const double m = double(i + 1);
      sum += series.ratio[i] * (previous + current);
      const double next = ((2 * m + 1) * mu * current - m * previous) / (m + 1);
      previous = current, current = next;
    }
    p.values.push_back(std::max(0.0, sum) / (4 * std::numbers::pi));  // / (4 pi g_1), g_1 factored out
  }
  return p;
}

std::vector<double> apsfBinned(const Medium& medium, const std::vector<double>& edges) {
  // Each bin's mean over solid angle: 16-point Gauss-Legendre in mu per bin.
  static const double x[8] = {0.0950125098376374, 0.2816035507792589, 0.4580167776572274, 0.6178762444026438,
                              0.7554044083550030, 0.8656312023878318, 0.9445750230732326, 0.9894009349916499};
  static const double w[8] = {0.1894506104550685, 0.1826034150449236, 0.1691565193950025, 0.1495959888165767,
                              0.1246289712555339, 0.0951585116824928, 0.0622535239386479, 0.0271524594117541};
  std::vector<double> out;
  for (size_t b = 0; b + 1 < edges.size(); ++b) {
    const double mu0 = std::cos(edges[b + 1]), mu1 = std::cos(edges[b]);
    const double mid = 0.5 * (mu0 + mu1), half = 0.5 * (mu1 - mu0);
    std::vector<double> angles;
    for (int i = 0; i < 8; ++i)
      angles.push_back(std::acos(std::clamp(mid - half * x[i], -1.0, 1.0))),
          angles.push_back(std::acos(std::clamp(mid + half * x[i], -1.0, 1.0)));
    const Profile p = apsf(medium, angles);
    double sum = 0;
    for (int i = 0; i < 8; ++i) sum += w[i] * (p.values[size_t(2 * i)] + p.values[size_t(2 * i + 1)]);
    out.push_back(0.5 * sum);  // the mean over [mu0, mu1] (weights sum to 2)
  }
  return out;
}

}  // namespace effects::glow
