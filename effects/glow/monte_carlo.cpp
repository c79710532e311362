// The APSF's independent check (glow.h): photons through the same medium, counted where they
// cross the unit sphere. Nothing here uses the series.
#include <algorithm>
#include <cmath>
#include <numbers>

#include "effects/glow.h"

namespace effects::glow {
namespace {

constexpr double kPi = std::numbers::pi;

// xoshiro256**, seeded by splitmix64: the same photons for the same seed on every machine.
class Random {
 public:
  explicit Random(uint64_t seed) {
    for (uint64_t& s : s_) {
      seed += 0x9E3779B97F4A7C15ull;
      uint64_t z = seed;
      z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
      z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
      s = z ^ (z >> 31);
    }
  }
  double uniform() {  // (0, 1)
    const uint64_t r = rotl(s_[1] * 5, 7) * 9, t = s_[1] << 17;
    s_[2] ^= s_[0], s_[3] ^= s_[1], s_[1] ^= s_[2], s_[0] ^= s_[3], s_[2] ^= t, s_[3] = rotl(s_[3], 45);
    return (double(r >> 11) + 0.5) * 0x1.0p-53;
  }

 private:
  static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }
  uint64_t s_[4];
};

struct Vec {
  double x, y, z;
};
Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator*(double s, Vec a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }

// A direction at cos theta = c from v (Henyey-Greenstein's inverse CDF), uniform in azimuth.
Vec scatter(Vec v, double g, Random& rng) {
  double c;
  if (std::abs(g) < 1e-6) {
    c = 2 * rng.uniform() - 1;
  } else {
    const double s = (1 - g * g) / (1 - g + 2 * g * rng.uniform());
    c = std::clamp((1 + g * g - s * s) / (2 * g), -1.0, 1.0);
  }
  const double sn = std::sqrt(std::max(0.0, 1 - c * c)), phi = 2 * kPi * rng.uniform();
  const Vec a = std::abs(v.z) < 0.9 ? Vec{0, 0, 1} : Vec{1, 0, 0};
  Vec u{v.y * a.z - v.z * a.y, v.z * a.x - v.x * a.z, v.x * a.y - v.y * a.x};
  u = (1 / std::sqrt(dot(u, u))) * u;
  const Vec w{v.y * u.z - v.z * u.y, v.z * u.x - v.x * u.z, v.x * u.y - v.y * u.x};
  return c * v + (sn * std::cos(phi)) * u + (sn * std::sin(phi)) * w;
}

}  // namespace

MonteCarlo monteCarlo(const Medium& medium, const MonteCarloOptions& o) {
  const int bins = std::max(1, o.bins);
  MonteCarlo out;
  for (int b = 0; b <= bins; ++b) out.edges.push_back(kPi * b / bins);
  std::vector<double> sum(size_t(bins), 0.0), squares(size_t(bins), 0.0), mine(static_cast<size_t>(bins));
  Random rng(o.seed);
  const double t = std::max(medium.thickness, 1e-9), q = medium.forwardScattering;
  const double escape2 = o.escape * o.escape;
  // Grazing crossings weigh 1/|mu|: capped at 1/kMinMu (the estimator's variance is infinite
  // otherwise); it touches the bins next to 90 degrees only.
  constexpr double kMinMu = 1e-2;
  int64_t direct = 0;
  for (int64_t n = 0; n < o.photons; ++n) {
    std::fill(mine.begin(), mine.end(), 0.0);
    Vec x{0, 0, 0}, v{0, 0, 1};  // any direction: the source is isotropic and the medium uniform
    bool scattered = false;
    for (int steps = 0; steps < 100000000; ++steps) {
      const double s = -std::log(rng.uniform()) / t;
      const double b = dot(x, v), c = dot(x, x) - 1, disc = b * b - c;
      if (disc > 0) {
        const double r = std::sqrt(disc);
        for (double at : {-b - r, -b + r})
          if (at > 0 && at <= s) {
            const Vec p = x + at * v;
            const double mu = std::clamp(dot(p, v) / std::sqrt(dot(p, p)), -1.0, 1.0);
            const int bin = std::min(bins - 1, int(std::acos(mu) / kPi * bins));
            mine[size_t(bin)] += 1 / std::max(std::abs(mu), kMinMu);
            if (!scattered) ++direct;
          }
      }
      x = x + s * v;
      if (dot(x, x) > escape2) break;
      v = scatter(v, q, rng);
      scattered = true;
    }
    for (int i = 0; i < bins; ++i) sum[size_t(i)] += mine[size_t(i)], squares[size_t(i)] += mine[size_t(i)] * mine[size_t(i)];
  }
  const double count = double(std::max<int64_t>(1, o.photons));
  double total = 0;
  for (double s : sum) total += s;
  for (int i = 0; i < bins; ++i) {
    const double omega = 2 * kPi * (std::cos(out.edges[size_t(i)]) - std::cos(out.edges[size_t(i + 1)]));
    const double mean = sum[size_t(i)] / count;
    const double variance = std::max(0.0, squares[size_t(i)] / count - mean * mean);
    const double scale = count / (total > 0 ? total : 1) / omega;  // the sphere's integral normalised to 1
    out.values.push_back(mean * scale);
    out.errors.push_back(std::sqrt(variance / count) * scale);
  }
  out.directShare = double(direct) / count;
  out.photons = o.photons;
  return out;
}

}  // namespace effects::glow
