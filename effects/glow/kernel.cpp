// Glow kernels a renderer can afford, each measured against the APSF series (glow.h): one to
// three Gaussians fitted per (T, q), or the series sampled into a radial table.
#include <algorithm>
#include <array>
#include <cmath>
#include <numbers>

#include "effects/glow.h"

namespace effects::glow {
namespace {

constexpr double kPi = std::numbers::pi;
constexpr int kFitSamples = 256;  // the fit's grid over (0, maxAngle]

struct Grid {
  std::vector<double> angles, weights;  // solid angle of each sample's ring (midpoint rule)
};
Grid gridOf(double maxAngle, int n) {
  Grid g;
  const double step = maxAngle / n;
  for (int i = 0; i < n; ++i) {
    const double a = (i + 0.5) * step;
    g.angles.push_back(a);
    g.weights.push_back(2 * kPi * std::sin(a) * step);
  }
  return g;
}

double gaussian(double angle, double sigma) {
  return std::exp(-angle * angle / (2 * sigma * sigma)) / (2 * kPi * sigma * sigma);
}

// The weights of Gaussians of these sigmas that best fit `target` (least squares, weighted by
// each ring's solid angle), none negative (every subset's solution, the best non-negative one);
// and the share of light they misplace.
struct Fit {
  std::vector<Gaussian> gaussians;
  double misplaced = INFINITY;
};
Fit fitWeights(const std::vector<double>& sigmas, const Grid& g, const std::vector<double>& target) {
  const size_t k = sigmas.size();
  std::vector<std::vector<double>> basis(k);
  for (size_t j = 0; j < k; ++j)
    for (double a : g.angles) basis[j].push_back(gaussian(a, sigmas[j]));
  Fit best;
  for (unsigned subset = 1; subset < (1u << k); ++subset) {
    std::vector<size_t> use;
    for (size_t j = 0; j < k; ++j)
      if (subset & (1u << j)) use.push_back(j);
    const size_t n = use.size();
    double a[3][4] = {};  // normal equations [A | b]
    for (size_t i = 0; i < g.angles.size(); ++i)
      for (size_t r = 0; r < n; ++r) {
        for (size_t c = 0; c < n; ++c) a[r][c] += g.weights[i] * basis[use[r]][i] * basis[use[c]][i];
        a[r][n] += g.weights[i] * basis[use[r]][i] * target[i];
      }
    bool ok = true;  // Gauss-Jordan with partial pivoting (n <= 3)
    for (size_t c = 0; c < n && ok; ++c) {
      size_t p = c;
      for (size_t r = c + 1; r < n; ++r)
        if (std::abs(a[r][c]) > std::abs(a[p][c])) p = r;
      if (!(std::abs(a[p][c]) > 1e-300)) ok = false;
      if (!ok) break;
      std::swap(a[c], a[p]);
      for (size_t r = 0; r < n; ++r)
        if (r != c) {
          const double f = a[r][c] / a[c][c];
          for (size_t cc = c; cc <= n; ++cc) a[r][cc] -= f * a[c][cc];
        }
    }
    if (!ok) continue;
    std::vector<Gaussian> gs;
    for (size_t r = 0; r < n && ok; ++r) {
      const double w = a[r][n] / a[r][r];
      if (!(w >= 0) || !std::isfinite(w)) ok = false;
      gs.push_back({w, sigmas[use[r]]});
    }
    if (!ok) continue;
    double misplaced = 0;
    for (size_t i = 0; i < g.angles.size(); ++i) misplaced += g.weights[i] * std::abs(gaussiansAt(gs, g.angles[i]) - target[i]);
    if (misplaced < best.misplaced) best = {std::move(gs), misplaced};
  }
  return best;
}

// Sigmas (ln-spaced search) minimising the misplaced light: a scan of each sigma in turn over
// [1e-4, 4] radians, then golden-section refinement, for a few sweeps.
Fit fitGaussians(int count, const Grid& g, const std::vector<double>& target) {
  const double lo = std::log(1e-4), hi = std::log(4.0);
  std::vector<double> ln(static_cast<size_t>(count));
  for (int j = 0; j < count; ++j) ln[size_t(j)] = std::log(0.02) + j * 1.2;  // 0.02, 0.066, 0.22 rad
  auto cost = [&](const std::vector<double>& l) {
    std::vector<double> s;
    for (double v : l) s.push_back(std::exp(v));
    return fitWeights(s, g, target);
  };
  Fit best = cost(ln);
  for (int sweep = 0; sweep < 4; ++sweep)
    for (size_t j = 0; j < ln.size(); ++j) {
      std::vector<double> trial = ln;
      double bestAt = ln[j];
      constexpr int kScan = 24;
      for (int i = 0; i <= kScan; ++i) {
        trial[j] = lo + (hi - lo) * i / kScan;
        Fit f = cost(trial);
        if (f.misplaced < best.misplaced) best = std::move(f), bestAt = trial[j];
      }
      double a = std::max(lo, bestAt - (hi - lo) / kScan), b = std::min(hi, bestAt + (hi - lo) / kScan);
      constexpr double kGolden = 0.6180339887498949;
      for (int i = 0; i < 30; ++i) {
        const double x1 = b - kGolden * (b - a), x2 = a + kGolden * (b - a);
        trial[j] = x1;
        Fit f1 = cost(trial);
        trial[j] = x2;
        Fit f2 = cost(trial);
        if (f1.misplaced < f2.misplaced) {
          b = x2;
          if (f1.misplaced < best.misplaced) best = std::move(f1), bestAt = x1;
        } else {
          a = x1;
          if (f2.misplaced < best.misplaced) best = std::move(f2), bestAt = x2;
        }
      }
      ln[j] = bestAt;
    }
  std::sort(best.gaussians.begin(), best.gaussians.end(), [](const Gaussian& x, const Gaussian& y) { return x.sigma < y.sigma; });
  return best;
}

double tableAt(const std::vector<double>& angles, const std::vector<double>& values, double angle) {
  if (angles.empty()) return 0;
  if (angle <= angles.front()) return values.front();
  if (angle >= angles.back()) return angle > angles.back() * (1 + 1e-12) ? 0.0 : values.back();
  const size_t i = size_t(std::upper_bound(angles.begin(), angles.end(), angle) - angles.begin());
  const double u = (angle - angles[i - 1]) / (angles[i] - angles[i - 1]);
  return values[i - 1] + u * (values[i] - values[i - 1]);
}

}  // namespace

double gaussiansAt(const std::vector<Gaussian>& gaussians, double angle) {
  double sum = 0;
  for (const Gaussian& g : gaussians) sum += g.weight * gaussian(angle, g.sigma);
  return sum;
}

const char* toString(Method m) {
  switch (m) {
    case Method::kGaussian: return "gaussian";
    case Method::kGaussians2: return "gaussians-2";
    case Method::kGaussians3: return "gaussians-3";
    case Method::kTable: return "table";
    case Method::kSeries: return "series";
  }
  return "?";
}

std::optional<Method> methodFromString(const std::string& name) {
  for (Method m : {Method::kGaussian, Method::kGaussians2, Method::kGaussians3, Method::kTable, Method::kSeries})
    if (name == toString(m)) return m;
  return std::nullopt;
}

double kernelAt(const Kernel& k, double angle) {
  if (angle > k.maxAngle * (1 + 1e-12)) return 0;
  return k.gaussians.empty() ? tableAt(k.angles, k.values, angle) : gaussiansAt(k.gaussians, angle);
}

Result<Kernel> kernel(const Medium& medium, const KernelOptions& o) {
  if (auto e = validate(medium)) return *e;
  if (!(o.maxAngle > 0 && o.maxAngle <= kPi)) return invalid("/maxAngle", "must be in (0, pi] radians");
  if (o.samples < 2 || o.samples > 4096) return invalid("/samples", "must be in [2, 4096]");
  Stopwatch watch;
  Kernel k;
  k.medium = medium;
  k.shapeThickness = shapeThickness(medium);
  k.direct = std::exp(-medium.thickness);
  k.scattered = -std::expm1(-medium.thickness);
  k.method = o.method;
  k.maxAngle = o.maxAngle;
  int terms = 0;
  if (o.method == Method::kTable || o.method == Method::kSeries) {
    for (int i = 0; i < o.samples; ++i) k.angles.push_back(o.maxAngle * i / (o.samples - 1));
    Profile p = apsf(medium, k.angles);
    k.values = std::move(p.values);
    terms = p.terms;
  } else {
    const Grid g = gridOf(o.maxAngle, kFitSamples);
    const Profile p = apsf(medium, g.angles);
    terms = p.terms;
    const int count = o.method == Method::kGaussian ? 1 : o.method == Method::kGaussians2 ? 2 : 3;
    k.gaussians = fitGaussians(count, g, p.values).gaussians;
  }
  // The halo's radius: half of the kernel's light within maxAngle, on a fine grid.
  const Grid fine = gridOf(o.maxAngle, 2048);
  std::vector<double> cumulative;
  double total = 0;
  for (size_t i = 0; i < fine.angles.size(); ++i) cumulative.push_back(total += fine.weights[i] * kernelAt(k, fine.angles[i]));
  for (size_t i = 0; i < cumulative.size(); ++i)
    if (cumulative[i] >= 0.5 * total) {
      k.haloRadius = fine.angles[i];
      break;
    }
  k.stats.method = toString(o.method);
  k.stats.counters["seriesTerms"] = terms;
  k.stats.elapsedMs = watch.ms();
  if (o.measureError) {
    Stopwatch errorWatch;
    // A grid 4x the table's (and never coarser than the fit's), midpoints: between the table's
    // entries, where linear interpolation is worst.
    const Grid check = gridOf(o.maxAngle, std::max(4 * o.samples, 4 * kFitSamples));
    const Profile exact = apsf(medium, check.angles);
    double misplaced = 0;
    for (size_t i = 0; i < check.angles.size(); ++i)
      misplaced += check.weights[i] * std::abs(kernelAt(k, check.angles[i]) - exact.values[i]);
    k.misplaced = misplaced;
    k.stats.error = misplaced;
    k.stats.errorMetric = "integral over [0, maxAngle] of |K - K_series| dOmega (the share of light misplaced)";
    k.stats.reference = "the APSF series (Narasimhan & Nayar 2003) at T = " + std::to_string(k.shapeThickness);
    k.stats.errorKind = "measured";
    k.stats.errorMs = errorWatch.ms();
  }
  return k;
}

}  // namespace effects::glow
