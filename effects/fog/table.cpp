// Fog colour tables: sampling, their interpolation error, and the smallest size for an error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

#include "effects/fog.h"

#include <glm/vec3.hpp>

namespace effects::fog {
namespace {

double dirYAt(const Table& t, double row) { return t.height == 1 ? 0.0 : -1.0 + 2.0 * row / double(t.height - 1); }
double distAt(const Table& t, double col) {
  if (col >= double(t.width - 1)) return t.rangeEnd;  // exactly: a cutoff at the end must not round past it
  return t.rangeStart + (t.rangeEnd - t.rangeStart) * col / double(t.width - 1);
}

double exact(const Fog& fog, double cameraHeight, double d, double dirY) {
  return factorAtElevation(fog, cameraHeight, dirY, d);
}

// One row of a height fog table (fixed ray elevation) without a logarithm per entry. Along the
// ray the optical depth is tau(t) = c (1 - e^{-k t}) / k with c the density at the camera and
// k = falloff * dirY, and e^{-k t} - 1 over evenly spaced t follows the recurrence
// M' = M + rho (M + 1), rho = e^{-k dt} - 1, which keeps its relative precision for small k t
// (no 1 - e^{-x} cancellation). That leaves one exp per entry. Rows where c or e^{|k| t}
// could overflow take the closed form per entry (heightOpticalDepth's log-space evaluation),
// as do fogs with a start distance, a second layer or an engine's convention.
bool fillHeightRow(const Fog& fog, double cameraHeight, double dirY, const Table& t, float* row) {
  const double a = fog.density, b = fog.heightFalloff;
  const double k = b * dirY;
  const double logC = a > 0.0 ? std::log(a) - b * (cameraHeight - fog.baseHeight) : 0.0;
  if (a == 0.0 || b == 0.0 || logC > 700.0 || std::fabs(k) * t.rangeEnd > 700.0) return false;
  if (fog.startDistance > 0.0 || fog.secondLayer || fog.convention != Convention::kEffectd) return false;
  if (k != 0.0 && std::fabs(k) < 1e-290) return false;  // -m/k would lose its precision in subnormals
  const double c = std::exp(logC);
  const double dt = (t.rangeEnd - t.rangeStart) / double(t.width - 1);
  const double rho = std::expm1(-k * dt);
  double m = std::expm1(-k * t.rangeStart);  // e^{-k t} - 1 at the first distance
  for (size_t i = 0; i < t.width; ++i) {
    const double d = i + 1 == t.width ? t.rangeEnd : t.rangeStart + dt * double(i);
    const double tau = k == 0.0 ? c * d : c * (-m / k);
    row[i] = static_cast<float>(engineLimits(fog, d, std::exp(-tau)));
    m += rho * (m + 1.0);
  }
  return true;
}

// One row of an ATMOSPHERIC table (f, T and S per channel; no dependence on elevation). Each
// channel's e^{-k d} over the evenly spaced distances follows e_{i+1} = e_i r, r = e^{-k dt},
// from an exponential at the first distance past the start and again at the last entry: two
// multiplications per channel and entry instead of an exponential. The values are those of
// factorAtElevation, transmittance and scattered up to rounding: over 4096 entries the
// relative drift stays under 1e-12, far below a float's 6e-8, so the stored floats agree with
// them to the last bit or one unit in it. Ranges that are not finite take the per-entry
// functions (returns false).
bool fillAtmosphericRow(const Fog& fog, Table& t, size_t j) {
  const size_t w = t.width;
  if (w < 2 || !std::isfinite(t.rangeStart) || !std::isfinite(t.rangeEnd) || !(t.rangeEnd > t.rangeStart)) return false;
  const double dt = (t.rangeEnd - t.rangeStart) / double(w - 1);
  glm::dvec3 ext(1.0), ins(1.0), stepExt, stepIns;
  for (int c = 0; c < 3; ++c) {
    stepExt[c] = std::exp(-(fog.extinction[c] * dt));
    stepIns[c] = std::exp(-(fog.inscattering[c] * dt));
  }
  bool anchored = false;
  for (size_t i = 0; i < w; ++i) {
    const double d = distAt(t, double(i));
    const double beyond = d - fog.startDistance;  // the ray's part past the start
    if (!(beyond > 0.0)) {
      ext = ins = glm::dvec3(1.0);
    } else if (!anchored || i + 1 == w) {
      for (int c = 0; c < 3; ++c) {
        ext[c] = std::exp(-(fog.extinction[c] * beyond));
        ins[c] = std::exp(-(fog.inscattering[c] * beyond));
      }
      anchored = true;
    } else {
      ext *= stepExt;
      ins *= stepIns;
    }
    const size_t e = j * w + i;
    double sum = 0.0;
    for (int c = 0; c < 3; ++c) {
      sum += ext[c];
      t.transmittanceRgb[3 * e + size_t(c)] = static_cast<float>(engineLimits(fog, d, ext[c]));
      t.scatteredRgb[3 * e + size_t(c)] = static_cast<float>((1.0 - engineLimits(fog, d, ins[c])) * fog.color[c]);
    }
    t.factor[e] = static_cast<float>(engineLimits(fog, d, sum / 3.0));
  }
  return true;
}

void fill(const Fog& fog, double cameraHeight, Table& t) {
  const size_t n = t.width * t.height;
  const bool rgb = fog.type == FogType::kAtmospheric;
  t.factor.resize(n);
  if (fog.directional) t.inscatter.resize(n);
  if (rgb) t.transmittanceRgb.resize(3 * n), t.scatteredRgb.resize(3 * n);
  for (size_t j = 0; j < t.height; ++j) {
    const double dirY = dirYAt(t, double(j));
    const bool rowDone = fog.type == FogType::kHeight ? fillHeightRow(fog, cameraHeight, dirY, t, &t.factor[j * t.width])
                                                      : rgb && fillAtmosphericRow(fog, t, j);
    for (size_t i = 0; i < t.width; ++i) {
      const size_t e = j * t.width + i;
      const double d = distAt(t, double(i));
      if (fog.directional) t.inscatter[e] = static_cast<float>(inscatterWeight(fog, cameraHeight, dirY, d));
      if (rowDone) continue;
      t.factor[e] = static_cast<float>(exact(fog, cameraHeight, d, dirY));
      if (!rgb) continue;
      const glm::dvec3 tr = transmittance(fog, cameraHeight, dirY, d), sc = scattered(fog, cameraHeight, dirY, d);
      for (int c = 0; c < 3; ++c) {
        t.transmittanceRgb[3 * e + size_t(c)] = static_cast<float>(tr[c]);
        t.scatteredRgb[3 * e + size_t(c)] = static_cast<float>(sc[c]);
      }
    }
  }
}

Result<Table> sized(const Fog& fog, const TableOptions& o, size_t width, size_t height, double start, double end) {
  Table t;
  t.width = width;
  t.height = height;
  t.rangeStart = start;
  t.rangeEnd = end;
  Stopwatch watch;
  fill(fog, o.cameraHeight, t);
  t.stats.elapsedMs = watch.ms();
  t.stats.method = std::string("table-") + toString(fog.type);
  t.stats.counters["entries"] = double(width * height);
  return t;
}

}  // namespace

double measureTableError(const Fog& fog, const Table& t, double cameraHeight, int sub, double* where) {
  double worst = 0.0, worstAt = t.rangeStart;

  const size_t rows = t.height == 1 ? 1 : (t.height - 1) * size_t(sub) + 1;
  const size_t cols = (t.width - 1) * size_t(sub) + 1;
  for (size_t r = 0; r < rows; ++r) {
    double row = t.height == 1 ? 0.0 : double(r) / sub;
    size_t j0 = std::min(size_t(row), t.height - 1), j1 = std::min(j0 + 1, t.height - 1);
    double fy = row - double(j0);
    for (size_t c = 0; c < cols; ++c) {
      double col = double(c) / sub;
      size_t i0 = std::min(size_t(col), t.width - 1), i1 = std::min(i0 + 1, t.width - 1);
      double fx = col - double(i0);
      auto lerp = [&](const std::vector<float>& v, size_t stride = 1, size_t channel = 0) {
        auto at = [&](size_t j, size_t i) { return double(v[stride * (j * t.width + i) + channel]); };
        double lerp0 = at(j0, i0) + (at(j0, i1) - at(j0, i0)) * fx;
        double lerp1 = at(j1, i0) + (at(j1, i1) - at(j1, i0)) * fx;
        return lerp0 + (lerp1 - lerp0) * fy;
      };
      double d = distAt(t, col);
      double e = std::fabs(lerp(t.factor) - exact(fog, cameraHeight, d, dirYAt(t, row)));
      if (!t.inscatter.empty())
        e = std::max(e, std::fabs(lerp(t.inscatter) - inscatterWeight(fog, cameraHeight, dirYAt(t, row), d)));
      if (!t.transmittanceRgb.empty()) {
        const glm::dvec3 tr = transmittance(fog, cameraHeight, dirYAt(t, row), d);
        const glm::dvec3 sc = scattered(fog, cameraHeight, dirYAt(t, row), d);
        for (size_t c = 0; c < 3; ++c)
          e = std::max({e, std::fabs(lerp(t.transmittanceRgb, 3, c) - tr[int(c)]),
                        std::fabs(lerp(t.scatteredRgb, 3, c) - sc[int(c)])});
      }
      if (e > worst) {
        worst = e;
        worstAt = d;
      }
    }
  }
  if (where) *where = worstAt;
  return worst;
}

namespace {

// A number for a message, to 3 significant digits ("2.31e-07", not to_string's "0.000000").
std::string shortNumber(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.3g", v);
  return buf;
}

// Table entries for N distances (and M elevations, for height fog's 2D tables).
size_t entries(bool twoD, size_t n, size_t m) { return n * (twoD ? m : 1); }

// Measures a table's interpolation error against the exact fog at `sub`x denser sampling.
void measure(const Fog& fog, const TableOptions& o, int sub, Table& t) {
  Stopwatch w;
  t.maxError = measureTableError(fog, t, o.cameraHeight, sub, &t.errorAtDistance);
  t.stats.counters["errorMs"] = w.ms();
  t.stats.error = t.maxError;
  t.stats.errorMetric = "max |lerp(table) - f| over " + std::to_string(sub) + "x denser sampling";
  t.stats.reference = "exact closed form";
}

// The table of the size asked for (o.size, and o.elevations for height fog).
Result<Table> fixedSize(const Fog& fog, const TableOptions& o, bool twoD, int sub, double start, double end) {
  size_t m = twoD ? (o.elevations ? o.elevations : o.size) : 1;
  if (o.size < 2 || (twoD && m < 2)) return invalid("/size", "must be >= 2");
  if (entries(twoD, o.size, m) > o.maxSize)
    return overLimit("/size", "table of " + std::to_string(entries(twoD, o.size, m)) +
                                  " entries exceeds the limit of " + std::to_string(o.maxSize));
  auto t = sized(fog, o, o.size, m, start, end);
  if (o.measureError) measure(fog, o, sub, t.value());
  return t;
}

// Smallest N with error <= maxError: double N until it meets the bound, then bisect.
// (Height fog tables stay square.) The error of linear interpolation falls like 1/N^2 for
// smooth f, so the search ends after a handful of measurements.
Result<Table> smallestForError(const Fog& fog, const TableOptions& o, bool twoD, int sub, double start, double end) {
  if (!(o.maxError > 0.0)) return invalid("/maxError", "must be > 0 when size is not given");
  Stopwatch total;
  auto errorFor = [&](size_t n) {
    auto t = sized(fog, o, n, twoD ? n : 1, start, end);
    measure(fog, o, sub, t.value());
    return t;
  };
  const size_t cap = twoD ? size_t(std::sqrt(double(o.maxSize))) : o.maxSize;  // largest N allowed
  size_t lo = 1, hi = 2;
  auto best = errorFor(hi);
  int measurements = 1;
  while (best.value().maxError > o.maxError) {
    lo = hi;
    if (entries(twoD, hi * 2, hi * 2) > o.maxSize) {
      if (cap <= hi) return unsatisfiable("/maxError", "not reachable within the table size limit");
      hi = cap;
    } else {
      hi *= 2;
    }
    best = errorFor(hi);
    ++measurements;
    if (best.value().maxError > o.maxError && hi == cap)
      return unsatisfiable("/maxError", "error " + shortNumber(best.value().maxError) + " at the size limit (" +
                                            std::to_string(entries(twoD, hi, hi)) + " entries) is above the requested maximum " +
                                            shortNumber(o.maxError));
  }
  while (hi - lo > 1) {
    size_t mid = lo + (hi - lo) / 2;
    auto t = errorFor(mid);
    ++measurements;
    if (t.value().maxError <= o.maxError) {
      hi = mid;
      best = std::move(t);
    } else {
      lo = mid;
    }
  }
  best.value().stats.counters["searchMeasurements"] = measurements;
  best.value().stats.counters["searchMs"] = total.ms();
  return best;
}

}  // namespace

Result<Table> buildTable(const Fog& fog, const TableOptions& o) {
  if (auto e = validate(fog)) return *e;
  const bool twoD = fog.type == FogType::kHeight;
  double start = o.rangeStart.value_or(0.0);
  double end = o.rangeEnd ? *o.rangeEnd : completeDistance(fog, o.cameraHeight);
  if (!std::isfinite(start) || start < 0.0) return invalid("/range/0", "must be a finite distance >= 0");
  // The contract's numbers stop at 1e300 (common.json's finite): a default range end beyond it
  // could not be sent back as the request's range.
  constexpr double kLargestDistance = 1e300;
  const bool x3d = fog.type == FogType::kX3dLinear || fog.type == FogType::kX3dExponential;
  if (!o.rangeEnd && x3d && fog.visibilityRange <= 0)  // X3D's rule: visibilityRange 0 turns the fog off
    return unsatisfiable("/visibilityRange", std::string("is 0, which turns X3D fog off (fogType ") + toString(fog.type) +
                                                 "; LINEAR is the default): give visibilityRange > 0, another "
                                                 "fogType, or table.range");
  if (!o.rangeEnd && !(std::isfinite(end) && end > start && end <= kLargestDistance))
    return unsatisfiable("/range", "this fog does not reach its densest (f = max(1/255, 1 - maxOpacity)) within "
                                   "1e300 beyond range[0]; give range explicitly");
  if (!std::isfinite(end) || !(end > start)) return invalid("/range/1", "must be finite and greater than range[0]");

  constexpr int kSub1D = 8, kSub2D = 4;
  const int sub = twoD ? kSub2D : kSub1D;
  if (o.size != 0) return fixedSize(fog, o, twoD, sub, start, end);
  return smallestForError(fog, o, twoD, sub, start, end);
}

}  // namespace effects::fog
