// Fog colour tables: sampling, their interpolation error, and the smallest size for an error.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>

#include "effects/fog.h"

#include <glm/vec3.hpp>

namespace effects::fog {

WarpedAxes warpedAxes(const Fog& fog, double cameraHeight, double rangeStart, double rangeEnd) {
  WarpedAxes a;
  a.end = rangeEnd;
  a.factorStart = std::clamp(fog.startDistance, rangeStart, rangeEnd);  // f = 1 nearer, in every convention
  a.inscatterStart = std::clamp(std::max(fog.startDistance, glowStart(fog)), rangeStart, rangeEnd);
  // The steepest layer that has fog, and its density at the camera in log space (a camera far
  // below the layer's base would overflow it). Far along a downward ray it is the densest;
  // nearer, another layer may add to it, which only shortens the distance to completeness.
  double logDensity = -std::numeric_limits<double>::infinity();
  auto add = [&](double density, double falloff, double base) {
    if (!(density > 0.0) || falloff < a.falloff) return;
    const double l = std::log(density) - falloff * (cameraHeight - base);
    logDensity = falloff > a.falloff ? l : std::max(logDensity, l);
    a.falloff = falloff;
  };
  add(fog.density, fog.heightFalloff, fog.baseHeight);
  if (fog.secondLayer) add(fog.secondLayer->density, fog.secondLayer->heightFalloff, fog.secondLayer->baseHeight);
  constexpr double kSpanOverComplete = 1.5;  // columns reach 1.5x the distance where f is complete
  // No height dependence (or a falloff so small, down to the denormals, that 1 / falloff is
  // beyond the doubles: the fog is uniform on any scale a double holds): even columns, rows.
  if (!(a.falloff > 0.0) || !std::isfinite(logDensity) || !std::isfinite(kSpanOverComplete / a.falloff)) {
    a.falloff = 0.0;
    return a;
  }
  // q: the optical depth at which the fog is complete, f = max(1/255, 1 - maxOpacity).
  const double q = -std::log(std::max(1.0 / 255.0, 1.0 - fog.maxOpacity));
  const double logKappa = std::log(q * a.falloff) - logDensity;
  a.lambda = kSpanOverComplete / a.falloff;
  // A camera so far above the fog that kappa would leave a float's range (a client computes
  // K x in float): clamping it would end downward rows far short of the fog, at f = 1. Even
  // columns instead (kappa 0: span = end - start), the rows still warped.
  a.kappa = logKappa > 69.0 ? 0.0 : std::exp(std::max(logKappa, -690.0));
  // At the far end a point's fog changes with elevation on the scale 1 / (falloff span); rows
  // spaced by asinh(K y) are 2 asinh(K) / (K (rows - 1)) apart there.
  a.rowK = std::clamp(0.5 * a.falloff * (rangeEnd - a.factorStart), 1.0, 1e6);
  return a;
}

const char* toString(TableOptions::Layout layout) {
  return layout == TableOptions::Layout::kWarped ? "warped" : "linear";
}

std::optional<TableOptions::Layout> layoutFromString(const std::string& name) {
  for (auto l : {TableOptions::Layout::kLinear, TableOptions::Layout::kWarped})
    if (name == toString(l)) return l;
  return std::nullopt;
}

size_t tableRows(const TableOptions& o, size_t size) {
  if (o.elevations) return o.elevations;
  return o.layout == TableOptions::Layout::kWarped ? std::max<size_t>(2, (size + 1) / 2) : size;
}

double warpedRowY(const WarpedAxes& a, double v) {
  return std::clamp(std::sinh(std::asinh(a.rowK) * (2.0 * v - 1.0)) / a.rowK, -1.0, 1.0);
}

double warpedSpan(const WarpedAxes& a, double y, double start) {
  const double full = std::max(a.end - start, 0.0);
  if (!(y < 0.0) || !(a.kappa > 0.0)) return full;
  const double k = a.kappa * std::exp(a.falloff * y * start);  // kappa at the row's start
  const double x = -k * y;
  const double lnOverX = x > 0.0 ? std::log1p(x) / x : 1.0;
  // A smooth minimum of the two: a kink in span(y) would be a kink along every column.
  const double l = a.lambda * k * lnOverX, lo = std::min(full, l), hi = std::max(full, l);
  return hi > 0.0 ? lo * std::pow(1.0 + std::pow(lo / hi, 8.0), -1.0 / 8.0) : 0.0;
}

namespace {

using Layout = TableOptions::Layout;

// Where row `row` and column `col` (fractional indices) of a table sit: the ray's y component,
// and the distance along it. A warped table's columns depend on the row's y and on the
// channel: the glow's columns begin where the glow does.
double rowY(const Table& t, double row) {
  if (t.height == 1) return 0.0;
  if (t.layout == Layout::kWarped) return warpedRowY(t.warped, row / double(t.height - 1));
  return -1.0 + 2.0 * row / double(t.height - 1);
}
struct Extent {
  double start, span, end;
};
Extent rowExtent(const Table& t, double y, bool glow) {
  if (t.layout == Layout::kLinear) return {t.rangeStart, t.rangeEnd - t.rangeStart, t.rangeEnd};
  const double start = glow ? t.warped.inscatterStart : t.warped.factorStart;
  return {start, warpedSpan(t.warped, y, start), t.warped.end};
}
double columnDistance(const Extent& e, size_t width, double col) {
  // exactly: a cutoff at the end must not round past it
  if (col >= double(width - 1)) return e.span >= e.end - e.start ? e.end : e.start + e.span;
  return e.start + e.span * col / double(width - 1);
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
bool fillHeightRow(const Fog& fog, double cameraHeight, double dirY, const Extent& e, size_t width, float* row) {
  const double a = fog.density, b = fog.heightFalloff;
  const double k = b * dirY;
  const double logC = a > 0.0 ? std::log(a) - b * (cameraHeight - fog.baseHeight) : 0.0;
  // The last column exactly where columnDistance puts it: start + span may round past a cutoff.
  const double rangeStart = e.start, rangeEnd = columnDistance(e, width, double(width - 1));
  if (width < 2 || a == 0.0 || b == 0.0 || logC > 700.0 || std::fabs(k) * rangeEnd > 700.0) return false;
  if (fog.startDistance > 0.0 || fog.secondLayer || fog.convention != Convention::kEffectd) return false;
  if (k != 0.0 && std::fabs(k) < 1e-290) return false;  // -m/k would lose its precision in subnormals
  const double c = std::exp(logC);
  const double dt = e.span / double(width - 1);
  const double rho = std::expm1(-k * dt);
  double m = std::expm1(-k * rangeStart);  // e^{-k t} - 1 at the first distance
  for (size_t i = 0; i < width; ++i) {
    const double d = i + 1 == width ? rangeEnd : rangeStart + dt * double(i);
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
  const Extent row = rowExtent(t, 0.0, false);
  for (size_t i = 0; i < w; ++i) {
    const double d = columnDistance(row, w, double(i));
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
    const double dirY = rowY(t, double(j));
    const Extent ef = rowExtent(t, dirY, false), eg = rowExtent(t, dirY, true);
    const bool rowDone = fog.type == FogType::kHeight
                             ? fillHeightRow(fog, cameraHeight, dirY, ef, t.width, &t.factor[j * t.width])
                             : rgb && fillAtmosphericRow(fog, t, j);
    for (size_t i = 0; i < t.width; ++i) {
      const size_t e = j * t.width + i;
      if (fog.directional)
        t.inscatter[e] =
            static_cast<float>(inscatterWeight(fog, cameraHeight, dirY, columnDistance(eg, t.width, double(i))));
      if (rowDone) continue;
      const double d = columnDistance(ef, t.width, double(i));
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
  if (fog.type == FogType::kHeight && o.layout == Layout::kWarped) {
    t.layout = Layout::kWarped;
    t.warped = warpedAxes(fog, o.cameraHeight, start, end);
  }
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
  auto note = [&](double e, double d) {
    if (e > worst) worst = e, worstAt = d;
  };
  const size_t rows = t.height == 1 ? 1 : (t.height - 1) * size_t(sub) + 1;
  const size_t cols = (t.width - 1) * size_t(sub) + 1;
  // A warped row's lookup holds its last column past the row's span, up to the range's end:
  // as many samples again there, evenly in distance.
  const size_t past = t.layout == Layout::kWarped ? cols : 0;
  for (size_t r = 0; r < rows; ++r) {
    double row = t.height == 1 ? 0.0 : double(r) / sub;
    size_t j0 = std::min(size_t(row), t.height - 1), j1 = std::min(j0 + 1, t.height - 1);
    double fy = row - double(j0);
    const double y = rowY(t, row);
    const Extent ef = rowExtent(t, y, false), eg = rowExtent(t, y, true);
    for (size_t c = 0; c < cols + past; ++c) {
      const bool beyond = c >= cols;
      double col = beyond ? double(t.width - 1) : double(c) / sub;
      size_t i0 = std::min(size_t(col), t.width - 1), i1 = std::min(i0 + 1, t.width - 1);
      double fx = col - double(i0);
      auto lerp = [&](const std::vector<float>& v, size_t stride = 1, size_t channel = 0) {
        auto at = [&](size_t j, size_t i) { return double(v[stride * (j * t.width + i) + channel]); };
        double lerp0 = at(j0, i0) + (at(j0, i1) - at(j0, i0)) * fx;
        double lerp1 = at(j1, i0) + (at(j1, i1) - at(j1, i0)) * fx;
        return lerp0 + (lerp1 - lerp0) * fy;
      };
      auto distance = [&](const Extent& e) {
        if (!beyond) return columnDistance(e, t.width, col);
        const double last = e.start + e.span, k = double(c - cols + 1) / double(past);
        return last + (e.end - last) * k;
      };
      const double d = distance(ef);
      if (beyond && !(d > ef.start + ef.span) && !(distance(eg) > eg.start + eg.span)) continue;
      note(std::fabs(lerp(t.factor) - exact(fog, cameraHeight, d, y)), d);
      if (!t.inscatter.empty()) {
        const double dg = distance(eg);
        note(std::fabs(lerp(t.inscatter) - inscatterWeight(fog, cameraHeight, y, dg)), dg);
      }
      if (!t.transmittanceRgb.empty()) {
        const glm::dvec3 tr = transmittance(fog, cameraHeight, y, d);
        const glm::dvec3 sc = scattered(fog, cameraHeight, y, d);
        for (size_t c3 = 0; c3 < 3; ++c3)
          note(std::max(std::fabs(lerp(t.transmittanceRgb, 3, c3) - tr[int(c3)]),
                        std::fabs(lerp(t.scatteredRgb, 3, c3) - sc[int(c3)])),
               d);
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

// Table entries for N distances (and M elevations, for height fog's 2D tables); SIZE_MAX where
// the product does not fit (any limit refuses it).
size_t entries(bool twoD, size_t n, size_t m) {
  if (twoD && m && n > std::numeric_limits<size_t>::max() / m) return std::numeric_limits<size_t>::max();
  return n * (twoD ? m : 1);
}

// Measures a table's interpolation error against the exact fog at `sub`x denser sampling.
void measure(const Fog& fog, const TableOptions& o, int sub, Table& t) {
  Stopwatch w;
  t.maxError = measureTableError(fog, t, o.cameraHeight, sub, &t.errorAtDistance);
  t.stats.errorMs = w.ms();
  t.stats.counters["errorMs"] = t.stats.errorMs;
  t.stats.error = t.maxError;
  t.stats.errorMetric = "max |lerp(table) - f| over " + std::to_string(sub) + "x denser sampling";
  t.stats.reference = "exact closed form";
  t.stats.errorKind = "measured";
}

// Without the measurement: linear interpolation's leading error term, |second difference| / 8,
// along each row and each column of the table itself (no evaluation of the fog; an estimate).
void estimate(Table& t) {
  double worst = 0;
  auto along = [&](const std::vector<float>& v, size_t count, size_t stride, size_t lines, size_t lineStride) {
    for (size_t l = 0; l < lines; ++l)
      for (size_t i = 1; i + 1 < count; ++i) {
        const size_t at = l * lineStride + i * stride;
        worst = std::max(worst, std::fabs(double(v[at - stride]) - 2.0 * v[at] + double(v[at + stride])) / 8);
      }
  };
  for (const std::vector<float>* v : {&t.factor, &t.inscatter}) {
    if (v->empty()) continue;
    along(*v, t.width, 1, t.height, t.width);  // along distance
    along(*v, t.height, t.width, t.width, 1);  // along elevation
  }
  t.maxError = worst;
  t.stats.error = worst;
  t.stats.errorMetric =
      "estimate of max |lerp(table) - f|: max |second difference| / 8 over the table's rows and columns";
  t.stats.reference = "none (not measured: table.measureError false)";
  t.stats.errorKind = "estimate";
}

// The table of the size asked for (o.size, and o.elevations for height fog).
Result<Table> fixedSize(const Fog& fog, const TableOptions& o, bool twoD, int sub, double start, double end) {
  size_t m = twoD ? tableRows(o, o.size) : 1;
  if (o.size < 2 || (twoD && m < 2)) return invalid("/size", "must be >= 2");
  if (entries(twoD, o.size, m) > o.maxSize)
    return overLimit("/size", "table of " + std::to_string(entries(twoD, o.size, m)) +
                                  " entries exceeds the limit of " + std::to_string(o.maxSize));
  auto t = sized(fog, o, o.size, m, start, end);
  if (!t.ok()) return t;
  if (o.measureError)
    measure(fog, o, sub, t.value());
  else
    estimate(t.value());
  return t;
}

// Smallest N with error <= maxError: double N until it meets the bound, then bisect. Height
// fog tables have N rows (kLinear, square), or the asked elevations, or N/2 rows (kWarped: its
// rows need fewer samples than its columns). The error of linear interpolation falls like
// 1/N^2 for smooth f, so the search ends after a handful of measurements.
Result<Table> smallestForError(const Fog& fog, const TableOptions& o, bool twoD, int sub, double start, double end) {
  if (!(o.maxError > 0.0)) return invalid("/maxError", "must be > 0 when size is not given");
  Stopwatch total;
  const bool warped = twoD && o.layout == Layout::kWarped;
  auto rowsFor = [&](size_t n) -> size_t {
    if (!twoD) return 1;
    return warped ? tableRows(o, n) : n;
  };
  auto cells = [&](size_t n) { return double(n) * double(rowsFor(n)); };
  auto errorFor = [&](size_t n) {
    auto t = sized(fog, o, n, rowsFor(n), start, end);
    measure(fog, o, sub, t.value());
    return t;
  };
  if (cells(2) > double(o.maxSize)) return unsatisfiable("/maxError", "not reachable within the table size limit");
  // The largest N allowed: from an estimate, then to the exact bound.
  size_t cap = !twoD          ? o.maxSize
               : !warped      ? size_t(std::sqrt(double(o.maxSize)))
               : o.elevations ? o.maxSize / o.elevations
                              : size_t(std::sqrt(2.0 * double(o.maxSize)));
  while (cap > 2 && cells(cap) > double(o.maxSize)) --cap;
  while (cells(cap + 1) <= double(o.maxSize)) ++cap;
  size_t lo = 1, hi = 2;
  auto best = errorFor(hi);
  int measurements = 1;
  while (best.value().maxError > o.maxError) {
    lo = hi;
    if (cells(hi * 2) > double(o.maxSize)) {
      if (cap <= hi) return unsatisfiable("/maxError", "not reachable within the table size limit");
      hi = cap;
    } else {
      hi *= 2;
    }
    best = errorFor(hi);
    ++measurements;
    if (best.value().maxError > o.maxError && hi == cap)
      return unsatisfiable("/maxError", "error " + shortNumber(best.value().maxError) + " at the size limit (" +
                                            std::to_string(size_t(cells(hi))) +
                                            " entries) is above the requested maximum " + shortNumber(o.maxError));
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
    return unsatisfiable("/visibilityRange", std::string("is 0, which turns X3D fog off (fogType ") +
                                                 toString(fog.type) +
                                                 "; LINEAR is the default): give visibilityRange > 0, another "
                                                 "fogType, or table.range");
  if (!o.rangeEnd && !(std::isfinite(end) && end > start && end <= kLargestDistance))
    return unsatisfiable("/range",
                         "this fog does not reach its densest (f = max(1/255, 1 - maxOpacity)) within "
                         "1e300 beyond range[0]; give range explicitly");
  if (!std::isfinite(end) || !(end > start)) return invalid("/range/1", "must be finite and greater than range[0]");

  constexpr int kSub1D = 8, kSub2D = 4;
  const int sub = twoD ? kSub2D : kSub1D;
  if (o.size != 0) return fixedSize(fog, o, twoD, sub, start, end);
  return smallestForError(fog, o, twoD, sub, start, end);
}

}  // namespace effects::fog
