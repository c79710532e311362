// The soap film's thickness over the bubble: gravity drainage swirled by a divergence-free
// flow (see effects/bubble.h, docs/effects.md section 3.3).
#include <algorithm>
#include <array>
#include <cmath>

#include <glm/geometric.hpp>

#include "effects/bubble.h"

namespace effects::bubble {
namespace {

using glm::dvec3;
constexpr double kPi = 3.14159265358979323846;
constexpr int kModes = 6;        // sines in the stream function
constexpr int kTraceSteps = 6;  // midpoint steps back through the flow: 0.6 nm from 48 steps

// psi(x, t) = sum a_m sin(w_m . x + phase_m(t)): smooth, seeded; its surface curl is the flow.
struct Stream {
  std::array<dvec3, kModes> w;
  std::array<double, kModes> a, phase, drift;  // phase at t, drift rad per second
};

Stream stream(const ThicknessOptions& o, double t) {
  Rng rng(o.seed, 0x7468696e6b6e6573ULL);
  Stream s;
  double norm = 0;
  for (int m = 0; m < kModes; ++m) {
    // A direction uniform on the sphere, a wavenumber in [1.5, 3.5] (a few swirls per bubble).
    const double z = 2 * rng.uniform() - 1, phi = 2 * kPi * rng.uniform(), r = std::sqrt(1 - z * z);
    const double k = 1.5 + 2 * rng.uniform();
    s.w[m] = k * dvec3(r * std::cos(phi), z, r * std::sin(phi));
    s.a[m] = 1 / k;
    norm += 1.0;
    const double p0 = 2 * kPi * rng.uniform(), speed = (0.5 + rng.uniform()) * o.swirlSpeed;
    s.drift[m] = rng.uniform() < 0.5 ? -speed : speed;
    s.phase[m] = std::fmod(p0 + (s.drift[m] < 0 ? -reducedPhase(-s.drift[m], t) : reducedPhase(s.drift[m], t)), 2 * kPi);
  }
  for (double& a : s.a) a /= std::sqrt(norm);  // |grad psi| ~ 1
  return s;
}

// The flow at x (unit) a time `back` seconds before the stream's t: x cross grad psi.
dvec3 velocity(const Stream& s, const dvec3& x, double back) {
  dvec3 g(0);
  for (int m = 0; m < kModes; ++m) g += s.a[m] * std::cos(glm::dot(s.w[m], x) + s.phase[m] - s.drift[m] * back) * s.w[m];
  return glm::cross(x, g);
}

double drainage(const Params& p, const ThicknessOptions& o, double y, double t) {
  double alpha = std::clamp(p.muSpeed * t, 0.0, 1.0);  // eqn 3; t < 0 counts as 0
  if (std::isnan(alpha)) alpha = 0;
  const double bottom = o.bottomStartNm + (o.bottomEndNm - o.bottomStartNm) * alpha;
  const double depth = std::clamp((1 - y) / 2, 0.0, 1.0);
  return bottom * std::sqrt(depth);
}

// Traces x back through the flow over one unit of flow time scaled by `swirl`.
double traced(const Params& p, const ThicknessOptions& o, const Stream& s, dvec3 x, double t) {
  if (o.swirl > 0) {
    const double h = 1.0 / kTraceSteps;
    for (int i = 0; i < kTraceSteps; ++i) {
      const double back = i * h;
      dvec3 mid = glm::normalize(x - 0.5 * h * o.swirl * velocity(s, x, back));
      x = glm::normalize(x - h * o.swirl * velocity(s, mid, back + 0.5 * h));
    }
  }
  return drainage(p, o, x.y, t);
}

dvec3 pointOf(double u, double v) {  // the mesh's equirectangular UVs, inverted
  const double theta = (1 - v) * kPi, phi = (u - 0.5) * 2 * kPi;
  return {std::sin(theta) * std::cos(phi), std::cos(theta), std::sin(theta) * std::sin(phi)};
}

}  // namespace

std::optional<Error> validate(const ThicknessOptions& o) {
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!in(o.bottomStartNm, 0, 1e5)) return invalid("/bottomStartNm", "must be in [0, 1e5]");
  if (!in(o.bottomEndNm, 0, 1e5)) return invalid("/bottomEndNm", "must be in [0, 1e5]");
  if (!in(o.swirl, 0, 10)) return invalid("/swirl", "must be in [0, 10]");
  if (!in(o.swirlSpeed, 0, 1e6)) return invalid("/swirlSpeed", "must be in [0, 1e6]");
  if (o.width < 4 || o.width > 4096) return invalid("/width", "must be in [4, 4096]");
  if (o.height < 2 || o.height > 4096) return invalid("/height", "must be in [2, 4096]");
  return std::nullopt;
}

double thicknessAt(const Params& p, const ThicknessOptions& o, const dvec3& point, double t) {
  const double l = glm::length(point);
  const dvec3 x = l > 0 && std::isfinite(l) ? point / l : dvec3(0, 1, 0);
  return traced(p, o, stream(o, std::isfinite(t) ? t : 0.0), x, t);
}

double equatorThickness(const Params& p, const ThicknessOptions& o, double t) { return drainage(p, o, 0.0, t); }

Result<ThicknessField> thicknessField(const Params& p, const ThicknessOptions& o, double t, Parallel* parallel) {
  if (auto e = validate(p)) return *e;
  if (auto e = validate(o)) return *e;
  if (!std::isfinite(t)) return invalid("/time", "must be finite");
  Stopwatch watch;
  const Stream s = stream(o, t);
  ThicknessField f;
  f.width = o.width;
  f.height = o.height;
  f.nm.resize(size_t(o.width) * size_t(o.height));
  forRange(parallel, size_t(o.height), 4, [&](size_t begin, size_t end) {
    for (size_t j = begin; j < end; ++j)
      for (int i = 0; i < o.width; ++i)
        f.nm[j * size_t(o.width) + size_t(i)] =
            float(traced(p, o, s, pointOf((i + 0.5) / o.width, (j + 0.5) / o.height), t));
  });
  f.stats.elapsedMs = watch.ms();
  f.stats.method = "drainage+swirl";
  f.stats.counters = {{"width", double(o.width)}, {"height", double(o.height)}};
  if (!o.measureError) return f;
  // The texture's error: a bilinear lookup (REPEAT in u, clamped in v) between texel centres
  // against the exact thickness there, on a 64 x 32 sub-grid offset from the centres.
  auto at = [&](int i, int j) {
    i = ((i % o.width) + o.width) % o.width;
    j = std::clamp(j, 0, o.height - 1);
    return double(f.nm[size_t(j) * size_t(o.width) + size_t(i)]);
  };
  double sum = 0;
  int n = 0;
  for (int b = 0; b < 32; ++b)
    for (int a = 0; a < 64; ++a) {
      const double u = (a + 0.37) / 64, v = (b + 0.61) / 32;
      const double x = u * o.width - 0.5, y = v * o.height - 0.5;
      const int i = int(std::floor(x)), j = int(std::floor(y));
      const double fx = x - i, fy = y - j;
      const double lookup = (at(i, j) * (1 - fx) + at(i + 1, j) * fx) * (1 - fy) +
                            (at(i, j + 1) * (1 - fx) + at(i + 1, j + 1) * fx) * fy;
      const double e = std::abs(lookup - traced(p, o, s, pointOf(u, v), t));
      sum += e, f.maxErrorNm = std::max(f.maxErrorNm, e), ++n;
    }
  f.meanErrorNm = sum / n;
  f.stats.error = f.maxErrorNm;
  f.stats.errorMetric = "max |bilinear texture - exact| nm, 64 x 32 points between texels";
  f.stats.reference = "thickness traced per point";
  f.stats.counters["meanErrorNm"] = f.meanErrorNm;
  return f;
}

}  // namespace effects::bubble
