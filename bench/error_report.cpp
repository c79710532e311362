// The error-against-run-time report: every effect's methods and settings on fixed seeds,
// run time (median and interquartile range of repeats, from 3 processes: timings.h) against
// error to that effect's reference. Writes
//   <out>/error-vs-time.md          a summary (Pareto fronts, a choice per budget), then a table,
//                                   a plot and a conclusion per section
//   <out>/error-vs-time.json        the same numbers, for tests and tools
//   <out>/error-vs-time/<name>.png  log-log plots drawn with gnuplot (Debian's gnuplot-nox)
//
//   build/bench/error_report [--quick] [--out DIR] [--no-plots] [--stamp TEXT]
// Default DIR is docs/. --quick is the reduced configuration the test suite runs. --stamp is the
// line naming the command, commit, date and machine (scripts/report.sh passes it). Every section
// comes from this one run: the report is regenerated whole (scripts/report.sh).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <map>
#include <sstream>
#include <string>
#include <vector>

#include <glm/geometric.hpp>
#include <nlohmann/json.hpp>

#include <effects/bubble.h>
#include <effects/fog.h>
#include <effects/glow.h>
#include <effects/lightning.h>
#include <effects/tangents.h>
#include <render/render.h>

#include "api/api_render.h"
#include "api/scene.h"
#include "contract/config.h"

#include "fixtures.h"
#include "timings.h"

namespace {

namespace fs = std::filesystem;
namespace lt = effects::lightning;
namespace fg = effects::fog;
namespace gw = effects::glow;
namespace tg = effects::tangents;
namespace bb = effects::bubble;
namespace rd = effects::render;
using nlohmann::json;

constexpr double kPi = 3.14159265358979323846;

struct Point {
  std::string series;     // one curve per series (a method, a fog type ...)
  std::string setting;    // what varies along the curve
  double ms = 0;          // median run time
  double error = 0;       // against the section's reference
  std::string note;       // extra column
  double q1 = 0, q3 = 0;  // the run time's interquartile range (repeats, or seeds for bolts)
  int repeats = 0;
  std::string group;  // what a client fixes before choosing (a grid, a fog type, a mesh): the
                      // summary's Pareto fronts and choices are per group
  size_t ticket = bench::Timings::kNone;  // its run times, once the timing processes have run
  double timeFactor = 1;                  // times x this = the section's unit (tangents: per 100k)
  std::vector<double> runMedians;         // each timing process's median
};

// Median and quartiles (linear between order statistics) of run times.
struct Timing {
  double median = 0, q1 = 0, q3 = 0;
  int n = 0;
};
// The value at fraction f of v's order statistics (linear between them).
double quantile(std::vector<double> v, double f) {
  if (v.empty()) return NAN;
  std::sort(v.begin(), v.end());
  const double at = f * double(v.size() - 1);
  const size_t i = size_t(at);
  return i + 1 < v.size() ? v[i] + (v[i + 1] - v[i]) * (at - double(i)) : v[i];
}
Timing spreadOf(const std::vector<double>& v) {
  Timing t;
  t.n = int(v.size());
  if (v.empty()) return t;
  t.median = quantile(v, 0.5), t.q1 = quantile(v, 0.25), t.q3 = quantile(v, 0.75);
  return t;
}
Point pointOf(std::string series, std::string setting, const Timing& t, double error, std::string note = "") {
  Point p;
  p.series = std::move(series), p.setting = std::move(setting), p.error = error, p.note = std::move(note);
  p.ms = t.median, p.q1 = t.q1, p.q3 = t.q3, p.repeats = t.n;
  return p;
}
// A point whose times come from the timing processes (see timings.h).
Point pointOf(std::string series, std::string setting, size_t ticket, double error, std::string note = "") {
  Point p = pointOf(std::move(series), std::move(setting), Timing{}, error, std::move(note));
  p.ticket = ticket;
  return p;
}
// Whether two run times are a tie: their interquartile ranges overlap.
bool tie(const Point& a, const Point& b) { return a.q1 <= b.q3 && b.q1 <= a.q3; }

// A sheet of bolts side by side, drawn after a section's table: the lightning-shape section's
// DBM and fast bolts on the same seeds, one sheet per layout (3-D: seen along z).
struct Sheet {
  std::string section, id, caption;
  int width = 0, height = 0;        // the grid's x and y extent
  std::vector<std::string> titles;  // per panel; panels fill rows of `columns`
  // Per panel, the tree's edges (x0, y0, x1, y1 at cell centres): branches, then main channel.
  std::vector<std::vector<std::array<float, 4>>> branches, main;
  std::vector<std::array<int, 4>> obstacles;  // x, y, width, height: runs of obstacle cells (2-D)
  int columns = 4;
};

struct Section {
  std::string id, title, reference, errorName, timeName, settingName, noteName;
  std::vector<Point> points;
  std::string conclusion;
  double timeScale = 1;  // ms -> the unit shown (1000 for us)
  std::vector<std::pair<std::string, std::string>> pictures = {};  // (caption, file under error-vs-time/)
};

// Every section's timed jobs (main runs them in kTimingProcesses processes once all have
// registered), and what keeps the compiler from dropping a timed result.
bench::Timings timings;
constexpr int kTimingProcesses = 3;
volatile double sink = 0;

// Each seed's bolt grown again, its own elapsed time (the time of `p` over seeds 1..seeds).
size_t timeBolts(const std::string& name, lt::Params p, int seeds) {
  return timings.add(name, [p, seeds]() mutable {
    std::vector<double> t;
    for (int seed = 1; seed <= seeds; ++seed) {
      p.seed = uint64_t(seed);
      if (auto b = lt::grow(p); b.ok()) t.push_back(b.value().stats.elapsedMs);
    }
    return t;
  });
}

std::string fmt(double v, int digits = 3) {
  if (v == 0) return "0";
  std::ostringstream s;
  s.precision(digits);
  s << v;
  return s.str();
}

// ---- lightning -----------------------------------------------------------------------------
struct LightningSetting {
  std::string series, setting;
  lt::Params params;
};

double dimensionOf(const lt::Bolt& b, int n) {
  std::vector<lt::Cell> cells;
  for (const auto& node : b.nodes) cells.push_back(node.cell);
  return b.depth ? lt::fractalDimension(cells, n, n, n) : lt::fractalDimension(cells, n, n);
}

// Mean and sample standard deviation.
std::pair<double, double> meanSd(const std::vector<double>& v) {
  double mean = 0, var = 0;
  for (double x : v) mean += x / double(v.size());
  for (double x : v) var += (x - mean) * (x - mean) / double(std::max<size_t>(1, v.size() - 1));
  return {mean, std::sqrt(var)};
}

// The start-to-target layout of an n^2 grid or, with `volume`, an n^3 one.
lt::Params layoutOf(int n, bool volume) { return volume ? fixtures::volumeLayout(n) : fixtures::lightningLayout(n); }

// The settings of one grid and neighbourhood: the calibrated default, the paper's constants
// and the curves through them (lifetime, eqn 8's base), charges (2-D), DBM's solver tolerances.
std::vector<LightningSetting> lightningSettings(bool quick, int n, int hood, bool volume) {
  auto layout = [&] {
    lt::Params p = layoutOf(n, volume);
    p.neighbourhood = hood;
    lt::calibrate(p);
    return p;
  };
  std::vector<LightningSetting> settings;
  const lt::Params calibrated = layout();
  settings.push_back({"fast calibrated",
                      "default: axisGrowth " + fmt(calibrated.axisGrowth, 3) + ", lifetime " +
                          (calibrated.lifetime ? std::to_string(calibrated.lifetime) : std::string("inf")),
                      calibrated});
  for (int life : {2, 4, 8, 0}) {  // the paper's base 2; lifetime 4 is the paper variant
    lt::Params p = layout();
    p.axisGrowth = lt::kPaperAxisGrowth;
    p.lifetime = life;
    settings.push_back(
        {"fast paper",
         (life == 4 ? "variant paper: lifetime 4" : "lifetime " + (life ? std::to_string(life) : std::string("inf"))),
         p});
  }
  for (double growth : {1.5, 1.25, 1.1, 1.0}) {  // eqn 8's base, candidates never expiring
    lt::Params p = layout();
    p.axisGrowth = growth;
    p.lifetime = 0;
    settings.push_back({"fast axisGrowth", "axisGrowth " + fmt(growth, 3), p});
  }
  if (!volume && (n <= 128 || hood == 8)) {  // charges is O(cells x candidates): ~10 s a bolt at 256^2
    lt::Params c = layout();
    c.method = lt::Method::kCharges;
    settings.push_back({"charges calibrated", "default: power " + fmt(lt::calibratedChargesEta(c), 3), c});
    c.chargesEta = c.eta;  // Kim et al.'s parameter at DBM's eta: space-filling
    settings.push_back({"charges paper", "variant paper: power " + fmt(c.eta, 3), c});
  }
  std::vector<double> tolerances;
  if (quick)
    tolerances = {1e-2, 1e-4, 1e-6};
  else if (n <= 128)
    tolerances = {1e-2, 1e-4, 1e-6, 1e-8};
  else
    tolerances = {1e-2, 1e-4};
  {  // the exact solve: direct while the fixed cells are few, then MGPCG
    lt::Params p = layout();
    p.method = lt::Method::kDbm;
    p.solver = lt::Solver::kCapacitance;
    settings.push_back({"dbm-capacitance", "default: exact, MGPCG at tol 1e-6 past its limit", p});
  }
  for (lt::Solver solver : {lt::Solver::kMgpcg, lt::Solver::kCg}) {
    if (solver == lt::Solver::kCg && (quick || volume || n > 64)) continue;
    for (double tol : tolerances) {
      lt::Params p = layout();
      p.method = lt::Method::kDbm;
      p.solver = solver;
      p.tolerance = tol;
      settings.push_back({std::string("dbm-") + lt::toString(solver), "tol " + fmt(tol, 1), p});
    }
  }
  return settings;
}

// Every setting over 10 seeds (3 in the quick run): D against DBM's (the default solver at
// tolerance 1e-8: exact while the capacitance method runs; the same neighbourhood, 10 seeds)
// and, up to 128^2, the mean per-step total-variation distance
// (its reference solve every step costs seconds per 256^2 bolt).
void lightningRows(bool quick, int n, int hood, bool volume, Section& tv, Section& fd) {
  const int seeds = quick ? 3 : 10;
  const std::string grid = std::to_string(n) + (volume ? "³, " : "², ") + std::to_string(hood) + "-nbhd";
  std::vector<double> refD;
  {
    lt::Params p = layoutOf(n, volume);
    p.neighbourhood = hood;
    p.method = lt::Method::kDbm;
    p.tolerance = 1e-8;
    for (int s = 1; s <= seeds; ++s) {
      p.seed = uint64_t(s);
      auto b = lt::grow(p);
      if (b.ok()) refD.push_back(dimensionOf(b.value(), n));
    }
  }
  const auto [dRef, dRefSd] = meanSd(refD);
  for (const auto& s : lightningSettings(quick, n, hood, volume)) {
    std::vector<double> dims, tvs;
    for (int seed = 1; seed <= seeds; ++seed) {
      lt::Params p = s.params;
      p.seed = uint64_t(seed);
      auto b = lt::grow(p);
      if (!b.ok()) continue;
      dims.push_back(dimensionOf(b.value(), n));
      if (n > 128) continue;
      p.measureError = true;
      auto e = lt::grow(p);
      if (e.ok()) tvs.push_back(e.value().stats.error.value_or(0));
    }
    const auto [mean, sd] = meanSd(dims);
    // One curve per method, grid and neighbourhood; the setting varies along it.
    const std::string series = s.series + " " + grid;
    const size_t t = timeBolts(series + " " + s.setting, s.params, seeds);  // over seeds: each a different bolt
    fd.points.push_back(pointOf(series, s.setting, t, std::abs(mean - dRef),
                                fmt(mean, 3) + " ± " + fmt(sd, 2) + " (" + std::to_string(dims.size()) + " seeds)"));
    fd.points.back().group = grid;
    if (tvs.empty()) continue;
    const auto [tvMean, tvSd] = meanSd(tvs);
    tv.points.push_back(
        pointOf(series, s.setting, t, tvMean, "± " + fmt(tvSd, 2) + " (" + std::to_string(tvs.size()) + " seeds)"));
    tv.points.back().group = grid;
  }
  fd.points.push_back(pointOf("dbm reference " + grid, "D_ref", Timing{}, 0,
                              fmt(dRef, 3) + " ± " + fmt(dRefSd, 2) + " (" + std::to_string(refD.size()) + " seeds)"));
  fd.points.back().group = grid;
}

void lightning(bool quick, Section& tv, Section& fd) {
  tv = {
      "lightning-tv",
      "Lightning: per-step candidate distribution against the converged Laplace solution",
      "the DBM distribution from a converged solve (MGPCG, relative residual 1e-10) on the same bolt state, every step",
      "mean total-variation distance per step",
      "ms per bolt (median)",
      "setting",
      "sd over seeds",
      {},
      {}};
  fd = {"lightning-fd",
        "Lightning: fractal dimension against DBM",
        "mean box-counting dimension D_ref of exact DBM (the default solver: the capacitance method while its limit "
        "allows, then MGPCG at tolerance 1e-8) at the same size and seeds",
        "abs(mean D − D_ref)",
        "ms per bolt (median)",
        "setting",
        "mean D +- sd",
        {},
        {}};
  const std::vector<int> sizes = quick ? std::vector<int>{32} : std::vector<int>{64, 128, 256};
  for (int n : sizes)
    for (int hood : {8, 4}) {
      std::fprintf(stderr, "           %d², %d-neighbourhood\n", n, hood);
      lightningRows(quick, n, hood, false, tv, fd);
    }
}

// A bolt's edges for a sheet: each node to its parent, at cell centres (3-D: seen along z).
void sheetPanel(Sheet& sheet, const lt::Bolt& bolt, const std::string& title) {
  std::vector<char> onMain(bolt.nodes.size(), 0);
  for (int n : bolt.mainChannel) onMain[size_t(n)] = 1;
  std::vector<std::array<float, 4>> branches, main;
  for (size_t i = 0; i < bolt.nodes.size(); ++i) {
    const lt::Node& n = bolt.nodes[i];
    if (n.parent < 0) continue;
    const lt::Cell a = bolt.nodes[size_t(n.parent)].cell, b = n.cell;
    (onMain[i] && onMain[size_t(n.parent)] ? main : branches)
        .push_back({float(a.x) + 0.5f, float(a.y) + 0.5f, float(b.x) + 0.5f, float(b.y) + 0.5f});
  }
  sheet.titles.push_back(title);
  sheet.branches.push_back(std::move(branches));
  sheet.main.push_back(std::move(main));
}

// What a player sees, against exact DBM over seeds: cells, tips and D (lt::shapeDistance: each
// difference in standard errors of the two means), in the geometries games use: the open
// layout the calibration grows, a point target off-axis, the ground (a target region: every
// bottom cell), a wall (example 04), a wide grid, 3-D towards a ground plane, and a 3-wide
// channel whose field ahead of the bolt falls far below double's range (DeepField). A bolt
// that fills its channel scores in the hundreds. Each layout also gets a sheet: the first
// seeds' DBM bolts above the calibrated fast method's.
void lightningShape(bool quick, Section& out, std::vector<Sheet>& sheets) {
  out = {"lightning-shape",
         "Lightning: cells, tips and D against exact DBM, in seed-noise units",
         "exact DBM (capacitance, then MGPCG at 1e-8; DeepField below 1e-8) on the same layout over as many seeds",
         "largest |mean difference| / standard error of cells, tips, D",
         "ms per bolt (median)",
         "setting",
         "cells, tips, D (method / DBM)",
         {},
         {}};
  const int seeds = quick ? 6 : 20, drawn = 4;
  struct Layout {
    std::string name, id;
    lt::Params params;
    bool tolerances = false;  // also DBM with MGPCG at loose tolerances
  };
  auto ground = [](lt::Params p) {  // every bottom cell (3-D: the bottom layer) a target
    p.targets.clear();
    p.targetRegion.assign(size_t(p.width) * size_t(p.height) * size_t(std::max(p.depth, 1)), 0);
    for (int z = 0; z < std::max(p.depth, 1); ++z)
      for (int x = 0; x < p.width; ++x)
        p.targetRegion[(size_t(z) * size_t(p.height) + size_t(p.height - 1)) * size_t(p.width) + size_t(x)] = 1;
    lt::calibrate(p);
    return p;
  };
  std::vector<Layout> layouts;
  for (int n : quick ? std::vector<int>{32} : std::vector<int>{64, 128})
    layouts.push_back({std::to_string(n) + "² open", "open-" + std::to_string(n), layoutOf(n, false), true});
  const int n = quick ? 32 : 128;
  {
    lt::Params p = layoutOf(n, false);
    p.start = {n / 4, 0};
    p.targets = {{3 * n / 4, n - 1}};
    lt::calibrate(p);
    layouts.push_back({std::to_string(n) + "² off-axis", "off-axis-" + std::to_string(n), p});
  }
  layouts.push_back({std::to_string(n) + "² ground", "ground-" + std::to_string(n), ground(layoutOf(n, false))});
  if (!quick) {
    lt::Params wall = layoutOf(96, false);  // examples/04-storm-over-water.json's bolt
    wall.start = {20, 0};
    wall.targets = {{70, 95}};
    wall.obstacles.assign(96 * 96, 0);
    for (int y = 40; y < 46; ++y)
      for (int x = 30; x < 66; ++x) wall.obstacles[size_t(y) * 96 + size_t(x)] = 1;
    lt::calibrate(wall);
    layouts.push_back({"96² wall (example 04)", "wall-96", wall});
    lt::Params wide = layoutOf(128, false);
    wide.width = 256;
    wide.start = {128, 0};
    layouts.push_back({"256 × 128 ground", "ground-256x128", ground(wide)});
    layouts.push_back({"32³ ground plane", "ground-32x32x32", ground(layoutOf(32, true))});
  }
  {
    const int length = quick ? 128 : 512;
    lt::Params c = layoutOf(32, false);
    c.width = 3, c.height = length;
    c.start = {1, 0};
    c.targets = {{1, length - 1}};
    lt::calibrate(c);
    layouts.push_back({"3 × " + std::to_string(length) + " channel", "channel", c, true});
  }
  for (const Layout& l : layouts) {
    Sheet sheet;
    sheet.section = out.id;
    sheet.id = "lightning-shape-" + l.id;
    sheet.width = l.params.width;
    sheet.height = l.params.height;
    sheet.columns = sheet.height * 4 < sheet.width * 3 ? 2 : 4;  // wide grids: larger panels
    sheet.caption = l.name + ": exact DBM (" + (sheet.columns == 4 ? "top row" : "top two rows") +
                    ") and fast calibrated (below), seeds 1 to " + std::to_string(drawn);
    if (!l.params.obstacles.empty() && !l.params.depth)  // the obstacles, as runs along rows
      for (int y = 0; y < sheet.height; ++y)
        for (int x = 0; x < sheet.width; ++x) {
          if (!l.params.obstacles[size_t(y) * size_t(sheet.width) + size_t(x)]) continue;
          int run = x;
          while (run < sheet.width && l.params.obstacles[size_t(y) * size_t(sheet.width) + size_t(run)]) ++run;
          sheet.obstacles.push_back({x, y, run - x, 1});
          x = run;
        }
    const bool drawSheet = l.params.width > 3;
    auto shapes = [&](lt::Params p, const char* label) {
      std::vector<lt::BoltShape> v;
      for (int seed = 1; seed <= seeds; ++seed) {
        p.seed = uint64_t(seed);
        auto b = lt::grow(p);
        if (!b.ok()) continue;
        v.push_back(lt::shapeOf(b.value(), p.width, p.height, p.depth));
        if (label && drawSheet && seed <= drawn)
          sheetPanel(sheet, b.value(), std::string(label) + " seed " + std::to_string(seed));
      }
      return v;
    };
    lt::Params ref = l.params;
    ref.method = lt::Method::kDbm;
    ref.tolerance = 1e-8;
    const auto refShapes = shapes(ref, "dbm");
    std::vector<std::pair<std::string, lt::Params>> settings;
    settings.push_back({"fast calibrated", l.params});
    lt::Params paper = l.params;
    paper.axisGrowth = lt::kPaperAxisGrowth, paper.lifetime = 4;
    settings.push_back({"fast paper (lifetime 4)", paper});
    if (!l.params.depth) {
      lt::Params charges = l.params;
      charges.method = lt::Method::kCharges;
      settings.push_back({"charges calibrated", charges});
    }
    for (double tol : l.tolerances ? std::vector<double>{1e-1, 1e-2, 1e-4} : std::vector<double>{}) {
      lt::Params d = l.params;
      d.method = lt::Method::kDbm, d.solver = lt::Solver::kMgpcg, d.tolerance = tol;
      settings.push_back({"dbm-mgpcg tol " + fmt(tol, 1), d});
    }
    for (const auto& [name, p] : settings) {
      const auto methodShapes = shapes(p, name == "fast calibrated" ? "fast" : nullptr);
      const auto d = lt::shapeDistance(methodShapes, refShapes);
      // Fewer than two bolts on a side (failed growths) have no spread to measure against.
      const double score = methodShapes.size() < 2 || refShapes.size() < 2 ? NAN : d.worst;
      const std::string note = fmt(d.mean.cells, 4) + " / " + fmt(d.refMean.cells, 4) + ", " + fmt(d.mean.tips, 3) +
                               " / " + fmt(d.refMean.tips, 3) + ", " + fmt(d.mean.dimension, 3) + " / " +
                               fmt(d.refMean.dimension, 3) + " (z " + fmt(d.cells, 2) + ", " + fmt(d.tips, 2) + ", " +
                               fmt(d.dimension, 2) + "; " + std::to_string(methodShapes.size()) + " seeds)";
      out.points.push_back(
          pointOf(name.substr(0, name.find(" tol")) + " " + l.name,
                  name.find(" tol") == std::string::npos ? "default" : name.substr(name.find(" tol") + 1),
                  timeBolts(name + " " + l.name, p, seeds), score, note));
      out.points.back().group = l.name;
    }
    out.points.push_back(pointOf("dbm exact " + l.name, "reference", timeBolts("dbm exact " + l.name, ref, seeds), 0,
                                 std::to_string(refShapes.size()) + " seeds"));
    out.points.back().group = l.name;
    if (drawSheet) sheets.push_back(std::move(sheet));
  }
}

// The same two sections for 3-D grids (26-neighbourhood): 32^3 (16^3 in the quick run).
void lightning3d(bool quick, Section& tv, Section& fd) {
  tv = {"lightning3d-tv",
        "Lightning in 3-D: per-step candidate distribution against the converged Laplace solution",
        "the 3-D DBM distribution from a converged solve (7-point Laplacian, MGPCG, relative residual 1e-10) on the "
        "same bolt state, every step",
        "mean total-variation distance per step",
        "ms per bolt (median)",
        "setting",
        "sd over seeds",
        {},
        {}};
  fd = {"lightning3d-fd",
        "Lightning in 3-D: fractal dimension against DBM",
        "mean box-counting dimension D_ref of 3-D DBM (the default solver: exact while the capacitance method runs, "
        "MGPCG at tolerance 1e-8 past it) at the same size and seeds",
        "abs(mean D − D_ref)",
        "ms per bolt (median)",
        "setting",
        "mean D +- sd",
        {},
        {}};
  lightningRows(quick, quick ? 16 : 32, 26, true, tv, fd);
}

// ---- fog --------------------------------------------------------------------------------------
fg::Fog fogOf(fg::FogType t) {
  fg::Fog f;
  f.type = t;
  f.visibilityRange = 100;
  f.start = 10, f.end = 100;
  f.density = 0.03;
  f.distanceCoefficient = 0.0005;
  f.heightFalloff = 0.2;
  f.extinction = {0.01, 0.02, 0.04};
  f.inscattering = {0.005, 0.015, 0.03};
  return f;
}

// One scene in each engine's convention against effectd's exact integral (fog.h, Convention):
// how far apart the engines really are for the same parameters. The scene: density 0.05,
// falloff 0.2, camera at 2, start distance 5, a sun glow (exponent 8) from 10, 74 rays from 20
// degrees down to 45 up, each at 12 distances from 1 to 2000.
void fogConventions(bool quick, Section& out) {
  out = {"fog-conventions",
         "Height fog: each engine's convention against effectd's exact integral",
         "effectd's convention: the exact optical depth over [startDistance, d], the glow capped like the fog",
         "max abs(difference), 74 rays x 12 distances",
         "µs for the 888 points (median)",
         "quantity",
         "",
         {},
         {},
         1000};
  fg::Fog base;
  base.type = fg::FogType::kHeight;
  base.density = 0.05, base.heightFalloff = 0.2, base.baseHeight = 0, base.startDistance = 5;
  fg::Directional sun;
  sun.exponent = 8.0, sun.startDistance = 10;
  base.directional = sun;
  const double cameraY = 2;
  std::vector<double> dirs, distances;
  for (int i = 0; i < 74; ++i) dirs.push_back(std::sin((-20.0 + 65.0 * i / 73.0) * M_PI / 180.0));
  for (int i = 0; i < 12; ++i) distances.push_back(std::pow(2000.0, i / 11.0));
  for (fg::Convention c : {fg::Convention::kEffectd, fg::Convention::kFilament, fg::Convention::kUnreal}) {
    fg::Fog f = base;
    f.convention = c;
    double worstF = 0, worstGlow = 0;
    for (double dy : dirs)
      for (double d : distances) {
        worstF = std::max(
            worstF, std::abs(fg::factorAtElevation(f, cameraY, dy, d) - fg::factorAtElevation(base, cameraY, dy, d)));
        worstGlow = std::max(
            worstGlow, std::abs(fg::inscatterWeight(f, cameraY, dy, d) - fg::inscatterWeight(base, cameraY, dy, d)));
      }
    const size_t t = timings.repeat(std::string("convention ") + fg::toString(c), quick ? 5 : 21, [=] {
      for (double dy : dirs)
        for (double d : distances)
          sink = sink + fg::factorAtElevation(f, cameraY, dy, d) + fg::inscatterWeight(f, cameraY, dy, d);
    });
    out.points.push_back(pointOf(fg::toString(c), "weight f", t, worstF));
    out.points.push_back(pointOf(fg::toString(c), "glow 1 − f_dir", t, worstGlow));
  }
}

void fog(bool quick, Section& tables, Section& march) {
  tables = {"fog-tables",
            "Fog: colour tables against the exact function",
            "the exact closed form, sampled 16x between table entries",
            "max abs(lerp(table) − f)",
            "µs per table (median)",
            "entries",
            "",
            {},
            {},
            1000};
  const std::vector<size_t> sizes =
      quick ? std::vector<size_t>{16, 64, 256} : std::vector<size_t>{16, 32, 64, 128, 256, 512, 1024, 2048, 4096};
  // One series: tables of every size for `f` (height fog's are 2-D, n x n linear or n x n/2
  // warped, up to the 65 536-entry bound), timed without and measured with the error pass.
  using Layout = fg::TableOptions::Layout;
  // A warped series joins its linear twin's group: the summary picks between layouts.
  auto series = [&](const fg::Fog& f, const std::string& name, Layout layout = Layout::kLinear,
                    double cameraHeight = 5) {
    const std::string group = layout == Layout::kWarped ? name.substr(0, name.rfind(" warped")) : name;
    const bool twoD = f.type == fg::FogType::kHeight;
    for (size_t n : sizes) {
      fg::TableOptions o;
      o.size = n;
      o.layout = layout;
      o.elevations = twoD ? fg::tableRows(o, n) : 0;
      if (twoD && n * o.elevations > o.maxSize) continue;
      o.cameraHeight = cameraHeight;
      o.measureError = false;
      const size_t t = timings.repeat(name + " " + std::to_string(n), quick ? 5 : 21, [f, o] { (void)fg::buildTable(f, o); });
      o.measureError = true;
      auto table = fg::buildTable(f, o);
      tables.points.push_back(pointOf(name, std::to_string(n) + (twoD ? " × " + std::to_string(o.elevations) : ""), t,
                                      table.ok() ? table.value().maxError : NAN));
      tables.points.back().group = group;
    }
  };
  for (fg::FogType t : {fg::FogType::kX3dLinear, fg::FogType::kX3dExponential, fg::FogType::kGlLinear,
                        fg::FogType::kGlExp, fg::FogType::kGlExp2, fg::FogType::kDistanceExp2,
                        fg::FogType::kDistanceGaussian, fg::FogType::kHeight, fg::FogType::kAtmospheric})
    series(fogOf(t), fg::toString(t));
  // The engine terms (fog.h): a start distance, an opacity cap, a cutoff, height fog's second
  // layer and the sun's glow, whose weight 1 - f_dir is a second channel of the same table
  // (the error is the worse of the two channels).
  for (fg::FogType t : {fg::FogType::kGlExp, fg::FogType::kHeight}) {
    fg::Fog f = fogOf(t);
    f.startDistance = 5;
    f.maxOpacity = 0.95;
    if (t == fg::FogType::kHeight)
      f.secondLayer = fg::HeightLayer{0.01, 0.05, 3};
    else
      f.cutoffDistance = 120;
    fg::Directional sun;
    sun.startDistance = 12;
    f.directional = sun;
    series(f, std::string(fg::toString(t)) + " + engine terms");
    if (t == fg::FogType::kHeight) {
      series(fogOf(t), "HEIGHT warped", Layout::kWarped);
      series(f, "HEIGHT + engine terms warped", Layout::kWarped);
    }
  }
  // Example 08's sunset (examples/08-sunset-fog.json, camera at 1.7): two layers, a start, a
  // cap and a glow from 10 m, in both layouts.
  fg::Fog sunset = fogOf(fg::FogType::kHeight);
  sunset.color = {0.42, 0.36, 0.42};
  sunset.density = 0.012;
  sunset.heightFalloff = 0.06;
  sunset.baseHeight = 0;
  sunset.startDistance = 3;
  sunset.maxOpacity = 0.97;
  sunset.secondLayer = fg::HeightLayer{0.05, 0.9, 0};
  fg::Directional glow;
  glow.color = {0.2, 0.1, 0.04};
  glow.direction = {0.02, 0.06, -1};
  glow.g = 0.55;
  glow.startDistance = 10;
  sunset.directional = glow;
  series(sunset, "HEIGHT sunset (example 08)", Layout::kLinear, 1.7);
  series(sunset, "HEIGHT sunset (example 08) warped", Layout::kWarped, 1.7);
  march = {"fog-height-march",
           "Height fog: closed-form optical depth against ray marching",
           "the closed form tau = a e^(-b(o_y-h)) t (1-e^(-x))/x (exact; checked against 200 000-step marching in the "
           "tests)",
           "max abs(f_marched − f_exact), 64 rays",
           "µs for 64 rays (median)",
           "steps",
           "",
           {},
           {},
           1000};
  const double a = 0.05, b = 0.3, h = 0, oy = 2, dist = 150;
  std::vector<double> dirs;
  for (int i = 0; i < 64; ++i) dirs.push_back(-0.3 + 0.6 * i / 63.0);
  auto exact = [=](double dy) { return std::exp(-fg::heightOpticalDepth(a, b, h, oy, dy, dist)); };
  const size_t closed = timings.repeat("height closed form", quick ? 5 : 51, [=] {
    for (double dy : dirs) sink = sink + exact(dy);
  });
  march.points.push_back(pointOf("closed form", "exact", closed, 0));
  for (int steps : quick ? std::vector<int>{4, 16, 64} : std::vector<int>{4, 8, 16, 32, 64, 128, 256, 512, 1024}) {
    double worst = 0;
    for (double dy : dirs)
      worst =
          std::max(worst, std::abs(std::exp(-fg::heightOpticalDepthMarched(a, b, h, oy, dy, dist, steps)) - exact(dy)));
    const size_t t = timings.repeat("height march " + std::to_string(steps), quick ? 5 : 21, [=] {
      for (double dy : dirs) sink = sink + std::exp(-fg::heightOpticalDepthMarched(a, b, h, oy, dy, dist, steps));
    });
    march.points.push_back(pointOf("ray marching", std::to_string(steps) + " steps", t, worst));
  }
}

// ---- tangents ----------------------------------------------------------------------------------
void tangents(bool quick, Section& out) {
  out = {"tangents",
         "Bump mapping: tangent frames against MikkTSpace",
         "MikkTSpace (effectd's implementation, checked against the npm mikktspace WASM build in the tests)",
         "mean angle between corner tangents, degrees",
         "ms per 100k triangles (median)",
         "mesh",
         "max angle, handedness mismatches",
         {},
         {}};
  struct M {
    std::string name;
    tg::Mesh mesh;
  };
  std::vector<M> meshes = {{"UV sphere", fixtures::uvSphere(quick ? 40 : 200, quick ? 50 : 250)},
                           {"mirrored bumpy torus", fixtures::mirroredTorus(quick ? 40 : 200, quick ? 50 : 250)}};
  for (const M& m : meshes) {
    const double per100k = 100000.0 / double(m.mesh.indices.size() / 3);
    for (tg::Mode mode : {tg::Mode::kMikkTSpace, tg::Mode::kPerVertex, tg::Mode::kPerTriangle}) {
      tg::Options o;
      o.mode = mode;
      const size_t t = timings.repeat(m.name + " " + tg::toString(mode), quick ? 5 : 9,
                                      [mesh = m.mesh, o] { (void)tg::generate(mesh, o); });
      Point p = pointOf(tg::toString(mode), m.name, t, 0, "—");
      p.timeFactor = per100k;
      p.group = m.name;
      if (mode != tg::Mode::kMikkTSpace) {
        o.measureError = true;
        auto r = tg::generate(m.mesh, o);
        const auto& st = r.value().stats;
        p.error = st.error.value_or(NAN);
        p.note = fmt(st.counters.at("maxAngleDeg"), 3) + "°, " + fmt(st.counters.at("handednessMismatches"), 6);
      }
      out.points.push_back(p);
    }
  }
}

// ---- soap bubble thin film ----------------------------------------------------------------------
void thinFilm(bool quick, Section& out) {
  out = {"thin-film",
         "Soap bubble: thin-film colour table against the spectral quadrature, films of 0-1000 nm and 99-100 um",
         "the spectral integral by Gauss-Legendre quadrature resolving every fringe (filmColorReference) at a 32 x 32 "
         "sub-grid of the timed table's own texels",
         "mean CIE76 ΔE*ab",
         quick ? "ms per 64² table (median)" : "ms per 256² table (median)",
         "wavelength samples",
         "max ΔE*ab",
         {},
         {}};
  for (int w : quick ? std::vector<int>{3, 8, 16}
                     : std::vector<int>{3, 4, 5, 6, 8, 11, 16, 23, 32, 45, 64, 81, 128, 200, 400}) {
    for (const bool thick : {false, true}) {
      bb::ThinFilmOptions o;
      o.width = o.height = quick ? 64 : 256;
      o.wavelengths = w;
      if (thick) o.thicknessMinNm = 99000, o.thicknessMaxNm = 100000;  // fringes finer than 1 nm
      o.measureError = false;
      const size_t time = timings.repeat("thin film " + std::to_string(w), quick ? 3 : 5, [o] { (void)bb::thinFilmTable(o); });
      o.measureError = true;  // the same table: its texels at a 32 x 32 sub-grid against the reference
      auto t = bb::thinFilmTable(o);
      out.points.push_back(pointOf(thick ? "Airy bands, 99-100 um" : "Airy bands, 0-1000 nm", std::to_string(w), time,
                                   t.value().meanDeltaE, fmt(t.value().maxDeltaE, 3)));
      out.points.back().group = thick ? "films of 99-100 um" : "films of 0-1000 nm";  // a client's film fixes it
    }
  }
  // Belcour & Barla's analytic form (filmColorAnalytic), which a shader could evaluate per
  // fragment instead of the table: its colours at 64 thicknesses x 32 angles over 0-1000 nm
  // against the same reference, timed for as many colours as a 256² table holds.
  const int side = quick ? 64 : 256;
  std::vector<double> de;
  for (int b = 0; b < 32; ++b)
    for (int a = 0; a < 64; ++a) {
      const double d = 1000.0 * (a + 0.5) / 64, c = 0.02 + 0.98 * (b + 0.5) / 32;
      de.push_back(bb::deltaE(bb::filmColorAnalytic(1.33, d, c), bb::filmColorReference(1.33, d, c)));
    }
  double mean = 0;
  for (double d : de) mean += d;
  const size_t t = timings.repeat("thin film analytic", quick ? 3 : 5, [side] {
    for (int j = 0; j < side; ++j)
      for (int i = 0; i < side; ++i) sink = sink + bb::filmColorAnalytic(1.33, 1000.0 * i / side, (j + 0.5) / side).x;
  });
  out.points.push_back(pointOf("analytic (Belcour & Barla 2017), 0-1000 nm", "closed form", t,
                               mean / double(de.size()), fmt(quantile(de, 1.0), 3)));
  out.points.back().group = "films of 0-1000 nm";
}

// ---- the glow through fog: the APSF ------------------------------------------------------------
// Each fast kernel against the series (the share of light it misplaces within 90 degrees), per
// medium; and the series itself against the photon simulation, the independent check.
void glowKernels(bool quick, Section& out) {
  out = {"glow-apsf",
         "Lightning glow through fog: APSF kernels against the series (Narasimhan & Nayar 2003), and the series "
         "against photons",
         "the APSF series summed to 1e-12 (glow::apsf) on a grid 4x the kernel's, over [0, 90 deg]; for the "
         "series row, glow::monteCarlo's photons in 30 bins over [0, 180 deg] (the whole sphere)",
         "light misplaced (integral of |K - K_ref| dOmega)",
         "ms per kernel (median)",
         "kernel",
         "halo radius (deg)",
         {},
         {}};
  struct Case {
    double t, q;
  };
  const std::vector<Case> cases = quick ? std::vector<Case>{{2, 0.9}} : std::vector<Case>{{1.2, 0.9}, {2, 0.9}, {4, 0.9}, {2, 0.5}, {8, 0.99}};
  for (const Case& c : cases) {
    const gw::Medium m{c.t, c.q};
    char group[64];
    std::snprintf(group, sizeof group, "T %g, q %g", c.t, c.q);
    for (gw::Method method : {gw::Method::kGaussian, gw::Method::kGaussians2, gw::Method::kGaussians3, gw::Method::kTable}) {
      for (int samples : method == gw::Method::kTable ? std::vector<int>{8, 32, 128} : std::vector<int>{64}) {
        gw::KernelOptions o;
        o.method = method;
        o.samples = samples;
        o.measureError = false;
        const size_t time = timings.repeat(std::string("glow ") + group + " " + gw::toString(method) + std::to_string(samples),
                                           quick ? 3 : 5, [m, o] { sink = sink + gw::kernel(m, o).value().haloRadius; });
        o.measureError = true;
        const gw::Kernel k = gw::kernel(m, o).value();
        const std::string setting = std::string(group) + ": " +
                                    (method == gw::Method::kTable ? "table of " + std::to_string(samples) : "fitted");
        out.points.push_back(pointOf(gw::toString(method), setting, time, *k.misplaced, fmt(k.haloRadius * 180 / kPi, 3)));
        out.points.back().group = group;
      }
    }
    // The series against the photons: the share of light the series puts elsewhere than they do.
    gw::MonteCarloOptions mo;
    mo.photons = quick ? 4000 : 40000;
    const gw::MonteCarlo mc = gw::monteCarlo(m, mo);
    const std::vector<double> series = gw::apsfBinned(m, mc.edges);
    double misplaced = 0, noise = 0;
    for (size_t b = 0; b < series.size(); ++b) {
      const double omega = 2 * kPi * (std::cos(mc.edges[b]) - std::cos(mc.edges[b + 1]));
      misplaced += omega * std::abs(series[b] - mc.values[b]);
      noise += omega * mc.errors[b];
    }
    const size_t time = timings.repeat(std::string("glow series ") + group, quick ? 3 : 5,
                                       [m, mc] { sink = sink + gw::apsfBinned(m, mc.edges).front(); });
    out.points.push_back(pointOf("series vs photons", std::string(group) + ": series (" + std::to_string(mo.photons) + " photons; their noise " +
                                                          fmt(noise, 2) + ")",
                                 time, misplaced, "—"));
    out.points.back().group = group;
  }
}

// ---- render previews --------------------------------------------------------------------------
// The bubble's GPU shading variants (/v1/render's bubble pass) against the physical reference
// (render::referenceRender), on one scene: a bubble at t = 7 s reflecting a sky in front of a
// dark backdrop, mesh level 4, the wobble off (the reference traces the analytic sphere).
struct Preview {
  std::string name;
  json bubble;
};
json previewScene(int size, const json& bubble) {
  return {{"width", size},
          {"height", size},
          {"time", 7},
          {"camera", {{"position", {0, 0.3, 4}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
          {"background", {{"gradient", {{"top", {0.18, 0.24, 0.2, 1}}, {"bottom", {0.08, 0.1, 0.07, 1}}}}}},
          {"environment", {{"zenith", {0.35, 0.6, 1.0}}, {"horizon", {1.0, 0.98, 0.95}}, {"ground", {0.16, 0.18, 0.12}}}},
          {"bubble", bubble}};
}
std::vector<Preview> previews() {
  const json still = {{"mesh", {{"level", 4}}}, {"features", {{"wobble", false}}}};
  auto with = [&](const json& features, const char* shading) {
    json b = still;
    b["features"].update(features);
    b["shading"] = shading;
    return b;
  };
  return {{"paper (eqns 3-11)", with(json::object(), "paper")},
          {"paper + film table", with({{"iridescence", true}}, "paper")},
          {"film, near side", with({{"backFace", false}, {"highlight", false}}, "film")},
          {"film + far side", with({{"highlight", false}}, "film")},
          {"film + far side + highlight (default)", with(json::object(), "film")}};
}
rd::Scene sceneOf(const json& scene);
rd::Scene previewOf(int size, const json& bubble) { return sceneOf(previewScene(size, bubble)); }

// Registers the frame times: each timing process makes its own renderer (a forked process
// cannot use the parent's), compiles each variant once untimed, then times `frames` frames
// (read-back included); the reference's time, on two threads, likewise.
void renderPreviewTimes(bool quick, Section& out) {
  out = {"render-bubble",
         "Render previews: the bubble's shading against the CPU reference renderer",
         "render::referenceRender: the analytic sphere ray traced on the CPU, the film per wavelength (400, 1 nm; Airy "
         "for s and p at the exact thickness of each point), the near film's reflection, the light through both films "
         "and the far film's reflection seen back through the near one (docs/rendering.md)",
         "mean CIE76 ΔE*ab over the bubble's pixels",
         quick ? "ms per 96² frame (median)" : "ms per 512² frame (median)",
         "shading",
         "p95 ΔE*ab; p95 3 px inside the silhouette",
         {},
         {}};
  const int size = quick ? 96 : 512, frames = quick ? 2 : 7;
  for (const Preview& v : previews()) {
    const size_t t = timings.add("render " + v.name, [size, frames, bubble = v.bubble] {
      static auto renderer = rd::Renderer::create();
      std::vector<double> ms;
      if (!renderer.ok()) return ms;
      for (int i = 0; i <= frames; ++i) {
        auto f = renderer.value()->render(previewOf(size, bubble));
        if (f.ok() && i > 0) ms.push_back(f.value().ms);  // the first compiles the variant
      }
      return ms;
    });
    out.points.push_back(pointOf(v.name, v.bubble["shading"].get<std::string>(), t, NAN));
  }
  const size_t ref = timings.add("render reference", [size] {
    effects::ThreadPool pool(2);
    std::vector<double> ms;
    for (int i = 0; i < 2; ++i)
      if (auto r = rd::referenceRender(previewOf(size, previews().back().bubble), &pool); r.ok())
        ms.push_back(r.value().ms);
    return ms;
  });
  out.points.push_back(pointOf("reference (CPU, 400 wavelengths, 2 threads)", "physical", ref, 0, "0; 0"));
}

// The errors, once the timing processes have run (this process's renderer is made here): each
// variant's frame (as its 8-bit PNG holds it) against the reference, and the pictures behind
// the numbers: the reference, the default's frame and its Delta E (grey = Delta E / 20, red > 20).
bool renderPreviewErrors(bool quick, Section& out, rd::Renderer& renderer, const fs::path& dir) {
  const int size = quick ? 96 : 512;
  effects::ThreadPool pool(2);
  auto ref = rd::referenceRender(previewOf(size, previews().back().bubble), &pool);
  if (!ref.ok()) return std::fprintf(stderr, "error_report: render previews: %s\n", ref.error().message.c_str()), false;
  const rd::Reference& reference = ref.value();
  // Pixels at least 3 away from the silhouette, where the mesh's polygon edge cannot differ.
  std::vector<uint8_t> interior;
  for (size_t p = 0; p < reference.bubble.size(); ++p) {
    if (!reference.bubble[p]) continue;
    const int x = int(p % size_t(size)), y = int(p / size_t(size));
    bool all = x >= 3 && y >= 3 && x < size - 3 && y < size - 3;
    for (int dy = -3; dy <= 3 && all; ++dy)
      for (int dx = -3; dx <= 3 && all; ++dx) all = reference.bubble[size_t(y + dy) * size_t(size) + size_t(x + dx)];
    interior.push_back(all);
  }
  const std::vector<Preview> variants = previews();
  fs::create_directories(dir);
  for (size_t i = 0; i < variants.size(); ++i) {
    auto f = renderer.render(previewOf(size, variants[i].bubble));
    if (!f.ok()) {
      std::fprintf(stderr, "error_report: %s: %s\n", variants[i].name.c_str(), f.error().message.c_str());
      return false;
    }
    const rd::Image frame = rd::Image{size, size, {}, rd::bytes8(f.value().image)};
    const std::vector<double> de = rd::bubbleDeltaE(frame, reference);
    std::vector<double> inside;
    for (size_t k = 0; k < de.size(); ++k)
      if (interior[k]) inside.push_back(de[k]);
    double mean = 0;
    for (double d : de) mean += d;
    out.points[i].error = de.empty() ? NAN : mean / double(de.size());
    out.points[i].note = fmt(quantile(de, 0.95), 3) + "; " + fmt(quantile(inside, 0.95), 3);
    if (i + 1 < variants.size()) continue;
    rd::Image map{size, size, std::vector<float>(size_t(size) * size_t(size) * 4, 1.0f), {}};
    for (size_t p = 0, k = 0; p < reference.bubble.size(); ++p) {
      const double d = reference.bubble[p] ? de[k++] : 0.0;
      for (int c = 0; c < 3; ++c) map.rgba[p * 4 + size_t(c)] = float(std::min(d / 20, 1.0));
      if (d > 20) map.rgba[p * 4 + 1] = map.rgba[p * 4 + 2] = 0;
    }
    for (auto [name, img] : {std::pair{"bubble-reference.png", &reference.image}, {"bubble-frame.png", &frame},
                             {"bubble-delta-e.png", &map}}) {
      auto png = rd::encodePng(*img, 8);
      if (!png.ok()) return false;
      std::ofstream(dir / name, std::ios::binary) << png.value();
    }
  }
  out.pictures = {{"the reference", "bubble-reference.png"},
                  {variants.back().name, "bubble-frame.png"},
                  {"ΔE*ab (grey = ΔE/20, red > 20)", "bubble-delta-e.png"}};
  return true;
}

// The fog pass (what the quad, wave and bubble passes apply, in float on the GPU) against the
// fog's closed form in double (fog::sampleAt): 24 small quads facing the camera, 3 to 40 m away
// across the view, each centre pixel against quad colour x transmittance + fog colour, in
// steps of 8-bit colour. Frame time as for the bubble.
struct FogPreview {
  std::string name;
  json fog;
};
std::vector<FogPreview> fogPreviews() {
  const json sun = {{"color", {1.5, 0.8, 0.3}}, {"direction", {0.3, 0.2, -1}}, {"exponent", 6}, {"startDistance", 5}};
  return {{"GL_EXP2", {{"fogType", "GL_EXP2"}, {"color", {0.6, 0.65, 0.7}}, {"density", 0.04}}},
          {"HEIGHT", {{"fogType", "HEIGHT"}, {"color", {0.55, 0.6, 0.7}}, {"density", 0.06}, {"heightFalloff", 0.3}}},
          {"HEIGHT + engine terms + sun",
           {{"fogType", "HEIGHT"},
            {"color", {0.55, 0.6, 0.7}},
            {"density", 0.06},
            {"heightFalloff", 0.3},
            {"startDistance", 4},
            {"maxOpacity", 0.9},
            {"secondLayer", {{"density", 0.03}, {"heightFalloff", 0.1}, {"baseHeight", 2}}},
            {"directional", sun}}},
          {"HEIGHT, filament convention + sun",
           {{"fogType", "HEIGHT"},
            {"convention", "filament"},
            {"color", {0.55, 0.6, 0.7}},
            {"density", 0.06},
            {"heightFalloff", 0.3},
            {"startDistance", 4},
            {"maxOpacity", 0.9},
            {"directional", sun}}},
          {"ATMOSPHERIC",
           {{"fogType", "ATMOSPHERIC"},
            {"color", {0.9, 0.7, 0.5}},
            {"extinction", {0.02, 0.05, 0.09}},
            {"inscattering", {0.01, 0.04, 0.08}}}}};
}
struct FogProbe {
  json scene;
  std::vector<glm::dvec3> points;
  std::vector<std::pair<int, int>> pixels;
};
FogProbe fogProbe(bool quick, const json& fogDef) {
  const int w = quick ? 128 : 512, h = w / 2;
  const double aspect = double(w) / h, tanHalf = std::tan(30.0 * kPi / 180), cameraY = 2;
  FogProbe f;
  f.scene = {{"width", w},
             {"height", h},
             {"camera", {{"position", {0, cameraY, 0}}, {"target", {0, cameraY, -1}}, {"fovY", 60}}},
             {"background", {{"color", {0, 0, 0}}}},
             {"fog", {{"fog", fogDef}}},
             {"quads", json::array()}};
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 6; ++col) {
      const double ndcX = -0.8 + 1.6 * col / 5, ndcY = -0.6 + 1.2 * row / 3;
      const double d = 3 + 37.0 * (row * 6 + col) / 23;
      const glm::dvec3 dir = glm::normalize(glm::dvec3(ndcX * tanHalf * aspect, ndcY * tanHalf, -1));
      const glm::dvec3 c = glm::dvec3(0, cameraY, 0) + dir * d;
      f.scene["quads"].push_back({{"center", {c.x, c.y, c.z}},
                                  {"normal", {-dir.x, -dir.y, -dir.z}},
                                  {"size", {0.06 * d, 0.06 * d}},
                                  {"color", {0.9, 0.6, 0.2}}});
      f.points.push_back(c);
      f.pixels.emplace_back(int(std::floor((ndcX * 0.5 + 0.5) * w)), int(std::floor((0.5 - ndcY * 0.5) * h)));
    }
  return f;
}
rd::Scene sceneOf(const json& scene) {
  static const effectd::Config config;
  const effectd::RequestContext ctx{"report", config};
  return effectd::buildScene(effectd::parseRenderRequest(scene, ctx), scene, ctx);
}

void fogPreviewTimes(bool quick, Section& out) {
  out = {"render-fog",
         "Render previews: the fog pass against the fog's closed form",
         "fog::sampleAt in double (the closed forms of docs/effects.md §2), at the centre of 24 quads 3 to 40 m away: "
         "quad colour x transmittance + fog colour",
         "max abs(pixel − closed form) over the quads, in steps of 8-bit colour",
         quick ? "ms per 128 × 64 frame (median)" : "ms per 512 × 256 frame (median)",
         "fog",
         "mean steps",
         {},
         {}};
  for (const FogPreview& v : fogPreviews()) {
    const size_t t = timings.add("render fog " + v.name, [quick, scene = fogProbe(quick, v.fog).scene] {
      static auto renderer = rd::Renderer::create();
      std::vector<double> ms;
      if (!renderer.ok()) return ms;
      for (int i = 0; i <= (quick ? 2 : 7); ++i)
        if (auto f = renderer.value()->render(sceneOf(scene)); f.ok() && i > 0) ms.push_back(f.value().ms);
      return ms;
    });
    out.points.push_back(pointOf(v.name, "GPU, float", t, NAN));
    out.points.back().group = v.name;
  }
}

bool fogPreviewErrors(bool quick, Section& out, rd::Renderer& renderer) {
  const std::vector<FogPreview> variants = fogPreviews();
  for (size_t i = 0; i < variants.size(); ++i) {
    const FogProbe probe = fogProbe(quick, variants[i].fog);
    const rd::Scene scene = sceneOf(probe.scene);
    auto f = renderer.render(scene);
    if (!f.ok()) return std::fprintf(stderr, "error_report: fog %s: %s\n", variants[i].name.c_str(),
                                     f.error().message.c_str()), false;
    const std::vector<uint8_t> px = rd::bytes8(f.value().image);
    double worst = 0, sum = 0;
    for (size_t q = 0; q < probe.points.size(); ++q) {
      const fg::Sample s = fg::sampleAt(scene.fog->global, scene.fog->regions, scene.camera.position, probe.points[q]);
      const auto [x, y] = probe.pixels[q];
      for (int c = 0; c < 3; ++c) {
        const double want = std::clamp(scene.quads[q].color[c] * s.transmittance[c] + s.fogColor[c], 0.0, 1.0);
        const double got = px[(size_t(y) * size_t(scene.width) + size_t(x)) * 4 + size_t(c)];
        const double steps = std::abs(got - want * 255);
        worst = std::max(worst, steps), sum += steps;
      }
    }
    out.points[i].error = worst;
    out.points[i].note = fmt(sum / double(3 * probe.points.size()), 3);
  }
  return true;
}

// ---- render previews: the lightning pass against its polylines --------------------------------
struct BoltPreview {
  std::string name;
  int grid, frame;
  double coreWidth;
};
std::vector<BoltPreview> boltPreviews(bool quick) {
  if (quick) return {{"64 grid, core 1.5", 64, 128, 1.5}};
  return {{"64 grid, core 1.5", 64, 256, 1.5}, {"64 grid, core 3", 64, 256, 3}, {"128 grid, core 1.5", 128, 512, 1.5}};
}
json boltScene(const BoltPreview& v) {
  return {{"width", v.frame},
          {"height", v.frame},
          {"background", {{"color", {0, 0, 0}}}},
          {"lightning",
           {{"grid", {{"width", v.grid}, {"height", v.grid}}}, {"start", {v.grid / 2, 0}}, {"targets", {{v.grid / 2, v.grid - 1}}},
            {"seed", 5}}},
          {"lightningStyle", {{"coreWidth", v.coreWidth}, {"glowSigma", 0}}}};
}

void lightningPreviewTimes(bool quick, Section& out) {
  out = {"render-lightning",
         "Render previews: the lightning pass against its polylines",
         "the answer's own polylines, mapped to pixels by the scene's rect: every bright pixel of the core (blue >= 64 "
         "of 255, glow off) measured against the nearest segment",
         "max over bright pixels of (distance to the nearest segment − coreWidth), px",
         "ms per frame (median)",
         "bolt",
         "segment midpoints lit",
         {},
         {}};
  for (const BoltPreview& v : boltPreviews(quick)) {
    const size_t t = timings.add("render lightning " + v.name, [quick, scene = boltScene(v)] {
      static auto renderer = rd::Renderer::create();
      std::vector<double> ms;
      if (!renderer.ok()) return ms;
      const rd::Scene built = sceneOf(scene);
      for (int i = 0; i <= (quick ? 2 : 7); ++i)
        if (auto f = renderer.value()->render(built); f.ok() && i > 0) ms.push_back(f.value().ms);
      return ms;
    });
    out.points.push_back(pointOf(v.name, std::to_string(v.frame) + "², GPU", t, NAN));
    out.points.back().group = v.name;
  }
}

bool lightningPreviewErrors(bool quick, Section& out, rd::Renderer& renderer) {
  const std::vector<BoltPreview> variants = boltPreviews(quick);
  for (size_t i = 0; i < variants.size(); ++i) {
    const rd::Scene scene = sceneOf(boltScene(variants[i]));
    auto f = renderer.render(scene);
    if (!f.ok() || !scene.lightning)
      return std::fprintf(stderr, "error_report: bolt %s did not render\n", variants[i].name.c_str()), false;
    const rd::Lightning& l = *scene.lightning;
    const int w = scene.width, h = scene.height;
    std::vector<std::pair<glm::dvec2, glm::dvec2>> segments;
    auto pixel = [&](const lt::Vertex& p) {
      return glm::dvec2((l.rect.x + p.x * (l.rect.z - l.rect.x) / l.gridWidth) * w,
                        (l.rect.y + p.y * (l.rect.w - l.rect.y) / l.gridHeight) * h);
    };
    for (const auto& line : l.polylines)
      for (size_t k = 1; k < line.vertices.size(); ++k)
        segments.push_back({pixel(line.vertices[k - 1]), pixel(line.vertices[k])});
    auto distance = [&](glm::dvec2 p) {
      double best = INFINITY;
      for (const auto& [a, b] : segments) {
        const glm::dvec2 ab = b - a;
        const double t = glm::dot(ab, ab) > 0 ? std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0) : 0.0;
        best = std::min(best, glm::length(p - (a + t * ab)));
      }
      return best;
    };
    const std::vector<uint8_t> px = rd::bytes8(f.value().image);
    auto blue = [&](int x, int y) { return px[(size_t(y) * size_t(w) + size_t(x)) * 4 + 2]; };
    double worst = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (blue(x, y) >= 64) worst = std::max(worst, distance({x + 0.5, y + 0.5}) - l.coreWidth);
    int lit = 0;
    for (const auto& [a, b] : segments) {
      const glm::dvec2 m = 0.5 * (a + b);
      lit += blue(std::clamp(int(m.x), 0, w - 1), std::clamp(int(m.y), 0, h - 1)) >= 51;
    }
    out.points[i].error = worst;
    out.points[i].note = fmt(100.0 * lit / double(std::max<size_t>(1, segments.size())), 3) + " %";
  }
  return true;
}

// ---- conclusions: read off the numbers ---------------------------------------------------------
// The fastest point within `maxError` among the series starting with `series`.
const Point* fastestWithin(const Section& s, double maxError, const std::string& series = "") {
  const Point* best = nullptr;
  for (const auto& p : s.points)
    if (p.series.rfind(series, 0) == 0 && p.error <= maxError && p.ms > 0 && (!best || p.ms < best->ms)) best = &p;
  return best;
}

void conclude(std::vector<Section>& sections) {
  for (Section& s : sections) {
    std::ostringstream c;
    const std::string unit = s.timeScale == 1000 ? " µs" : " ms";
    auto show = [&](const Point& p) {
      return p.series + " " + p.setting + " (" + fmt(p.ms * s.timeScale) + unit + ", error " + fmt(p.error) + ")";
    };
    if (s.id == "lightning-tv" || s.id == "lightning3d-tv") {
      const Point* good = fastestWithin(s, 0.05);
      const Point* fast = fastestWithin(s, 1.0, "fast paper");
      if (good && fast)
        c << "Fastest setting within a TV distance of 0.05 of the converged distribution: " << show(*good)
          << "; the paper's fast method costs " << fmt(fast->ms) << " ms but its distribution is far from DBM's (TV "
          << fmt(fast->error) << "): it is a different growth law, not an approximation that converges.";
    } else if (s.id == "lightning-fd" || s.id == "lightning3d-fd") {
      const Point* best = nullptr;
      for (const auto& p : s.points)
        if (p.ms > 0 && p.series.rfind("dbm", 0) != 0 && (!best || p.error < best->error)) best = &p;
      if (best) c << "Closest to DBM's dimension without a linear solve: " << show(*best) << ".";
      c << " The calibrated default against DBM in its neighbourhood (|D − D_ref|; the paper variant):";
      for (const auto& p : s.points) {
        if (p.series.rfind("fast calibrated", 0) != 0) continue;
        const std::string grid = p.series.substr(std::string("fast calibrated ").size());
        c << " " << grid << " " << fmt(p.error, 2);
        for (const auto& q : s.points)
          if (q.series == "fast paper " + grid && q.setting.rfind("variant paper", 0) == 0)
            c << " (" << fmt(q.error, 2) << ")";
        c << ";";
      }
      // Per DBM curve: the loosest tolerance from which |D - D_ref| stays within 0.03.
      std::map<std::string, std::string> settles;
      for (const auto& p : s.points) {
        if (p.series.rfind("dbm-", 0) != 0) continue;
        if (p.error > 0.03)
          settles[p.series] = "";
        else if (settles[p.series].empty())
          settles[p.series] = p.setting;
      }
      c << " DBM's dimension stays within 0.03 of D_ref from";
      for (const auto& [series, setting] : settles)
        c << " " << series << ": " << (setting.empty() ? "never" : setting) << ";";
      c << " looser solves grow visibly different (bushier) bolts.";
    } else if (s.id == "fog-tables") {
      c << "Smallest table meeting 8-bit precision (max error ≤ 1/255) per type:";
      std::map<std::string, const Point*> best;
      for (const auto& p : s.points)
        if (p.error <= 1.0 / 255 && (!best[p.series] || p.ms < best[p.series]->ms)) best[p.series] = &p;
      for (const auto& p : s.points) best.emplace(p.series, nullptr);
      for (const auto& [series, p] : best) {
        if (p)
          c << " " << series << " " << p->setting << " (" << fmt(p->ms * 1000) << " µs);";
        else
          c << " " << series << " none up to "
            << std::prev(
                   std::find_if(s.points.rbegin(), s.points.rend(), [&](const Point& q) { return q.series == series; })
                       .base())
                   ->setting
            << ";";
      }
      const Point* slowest = nullptr;
      for (const auto& p : s.points)
        if (!slowest || p.ms > slowest->ms) slowest = &p;
      const Point* quickest = fastestWithin(s, 1.0);
      if (slowest && quickest)
        c << " a table costs " << fmt(quickest->ms * 1000) << " µs (" << quickest->series << " " << quickest->setting
          << ") to " << fmt(slowest->ms * 1000) << " µs (" << slowest->series << " " << slowest->setting
          << "); below a millisecond, size a table by its error bound, not by its time.";
    } else if (s.id == "fog-conventions") {
      c << "For one scene with the same parameters:";
      for (const auto& p : s.points)
        if (p.series != "effectd")
          c << " " << p.series << "'s " << p.setting << " is up to " << fmt(p.error) << " from effectd's;";
      c << " the engines' start distance and glow differ (docs/effects.md §2.4); all three cost about the same.";
    } else if (s.id == "fog-height-march") {
      const Point* exact = &s.points.front();
      const Point* enough = fastestWithin(s, 1.0 / 255, "ray marching");
      c << "The closed form is exact and costs " << fmt(exact->ms * 1000) << " µs for 64 rays";
      if (enough)
        c << "; ray marching needs " << enough->setting << " for 8-bit precision at " << fmt(enough->ms * 1000)
          << " µs";
      c << ": the closed form wins on both axes.";
    } else if (s.id == "tangents") {
      double mikk = 0, vert = 0, vertErr = 0, triErr = 0;
      for (const auto& p : s.points) {
        if (p.setting != s.points.front().setting) continue;
        if (p.series == "mikktspace") mikk = p.ms;
        if (p.series == "perVertex") vert = p.ms, vertErr = p.error;
        if (p.series == "perTriangle") triErr = p.error;
      }
      const Point *mikkP = nullptr, *vertP = nullptr;
      for (const auto& p : s.points)
        if (p.setting == s.points.front().setting) {
          if (p.series == "mikktspace") mikkP = &p;
          if (p.series == "perVertex") vertP = &p;
        }
      c << "On the smooth sphere perVertex ";
      if (mikkP && vertP && tie(*mikkP, *vertP))
        c << "ties with MikkTSpace in time (their interquartile ranges overlap: " << fmt(vert) << " and " << fmt(mikk)
          << " ms)";
      else
        c << "is " << fmt(mikk / std::max(vert, 1e-9), 2) << "× as fast as MikkTSpace";
      c << " at a mean " << fmt(vertErr, 2) << "° (perTriangle " << fmt(triErr, 2)
        << "°); normal maps are baked in MikkTSpace, any mismatch shows as seams, and mirrored UVs break the "
           "averaged frames (see the torus): MikkTSpace is the default.";
    } else if (s.id == "lightning-shape") {
      c << "Indistinguishable from exact DBM at these seeds (every measure within 2 standard errors):";
      bool any = false;
      for (const auto& p : s.points)
        if (p.setting != "reference" && p.error <= 2) c << " " << p.series << " " << p.setting << ";", any = true;
      if (!any) c << " none;";
      c << " furthest:";
      const Point* far = nullptr;
      for (const auto& p : s.points)
        if (p.setting != "reference" && std::isfinite(p.error) && (!far || p.error > far->error)) far = &p;
      if (far)
        c << " " << far->series << " " << far->setting << " (" << fmt(far->error, 3)
          << " standard errors: " << far->note << ").";
      c << " The calibrated tables stay the fast method's default: no law measured meets DBM in every geometry. "
           "Seven shape measures per geometry and the laws tried: docs/lightning-shape.md.";
    } else if (s.id == "render-bubble") {
      const Point* best = nullptr;
      for (const auto& p : s.points)
        if (p.error > 0 && (!best || p.error < best->error)) best = &p;
      if (best)
        c << "Closest to the physical bubble: " << best->series << " (" << fmt(best->ms) << " ms, mean ΔE "
          << fmt(best->error, 3) << "), about "
          << fmt(s.points.back().ms / std::max(best->ms, 1e-9), 2)
          << "× faster than the reference. The paper's model is a look, not a film: its refraction bends the backdrop "
             "as solid water would, and its film table is added without taking transmitted light away. The film "
             "model's error sits along the rim (grazing angles, the polygon silhouette, the left-out inside bounces).";
    } else if (s.id == "render-fog") {
      double worst = 0;
      for (const auto& p : s.points) worst = std::max(worst, p.error);
      c << "The fog pass is the closed form in float: every fog here within " << fmt(worst, 2)
        << " steps of 8-bit colour of the double-precision closed form at the quads' centres; its cost is the "
           "frame's.";
    } else if (s.id == "render-lightning") {
      double worst = 0;
      for (const auto& p : s.points) worst = std::max(worst, p.error);
      c << "Every bright pixel of the core lies within coreWidth + " << fmt(worst, 3)
        << " px of the answer's polylines (the bound /v1/render states is 1.75 px: half a width of caps and one of "
           "anti-aliasing); the lit share of segment midpoints shows the bolt is drawn, not just kept inside.";
    } else if (s.id == "glow-apsf") {
      double worstSeries = 0, worstFit = 0;
      for (const auto& p : s.points) {
        if (p.series == "series vs photons") worstSeries = std::max(worstSeries, p.error);
        if (p.series == "gaussians-3") worstFit = std::max(worstFit, p.error);
      }
      c << "Three fitted Gaussians misplace at most " << fmt(worstFit, 2)
        << " of the light against the series (the renderer's default), a 32-entry table less and in a hundredth of "
           "the time (the fit is the cost). The series itself is not the physics: against photons through the same "
           "medium it misplaces up to "
        << fmt(worstSeries, 2)
        << " of the light, of at most 2 (its halo is too wide: at large T it tends to (1 + mu), where diffusion gives T(1 - q) + mu; "
           "docs/effects.md §5).";
    } else if (s.id == "thin-film") {
      const Point* jnd = fastestWithin(s, 1.0);
      if (jnd)
        c << "Fewest bands with a mean ΔE below 1 (about one just-noticeable difference): " << jnd->setting << " ("
          << jnd->series << ") at " << fmt(jnd->ms) << " ms per table; effectd's default is 16. "
          << "At 99-100 um every count is the incoherent grey within ΔE 1: the band means do not alias.";
    }
    s.conclusion = c.str();
  }
}

// ---- output -------------------------------------------------------------------------------------
// A section's time as shown: the median and, over several repeats, its interquartile range.
std::string timeText(const Section& s, const Point& p) {
  if (p.ms <= 0) return "—";
  std::string t = fmt(p.ms * s.timeScale);
  if (p.repeats > 1) t += " [" + fmt(p.q1 * s.timeScale) + ", " + fmt(p.q3 * s.timeScale) + "]";
  if (p.runMedians.size() > 1) {
    t += " (";
    for (size_t i = 0; i < p.runMedians.size(); ++i) t += (i ? " · " : "") + fmt(p.runMedians[i] * s.timeScale);
    t += ")";
  }
  return t;
}

// The points of a group that no other point beats on both axes (as fast or faster, or tied in
// time, and strictly closer), fastest first.
std::vector<const Point*> paretoFront(const Section& s, const std::string& group) {
  std::vector<const Point*> pts;
  for (const auto& p : s.points)
    if (p.group == group && p.ms > 0 && std::isfinite(p.error)) pts.push_back(&p);
  std::sort(pts.begin(), pts.end(),
            [](const Point* a, const Point* b) { return a->ms < b->ms || (a->ms == b->ms && a->error < b->error); });
  // Slower but tied in time (interquartile ranges overlap) and closer: it takes the faster's place.
  std::vector<const Point*> front;
  for (const Point* p : pts) {
    if (!front.empty() && !(p->error < front.back()->error)) continue;
    while (!front.empty() && tie(*front.back(), *p) && p->error < front.back()->error) front.pop_back();
    front.push_back(p);
  }
  return front;
}

// The budgets a client chooses by: a slice of a frame, a loading screen, offline baking.
struct Budget {
  const char* name;
  double ms;
};
constexpr Budget kBudgets[] = {
    {"interactive (≤ 1 ms)", 1.0}, {"loading screen (≤ 100 ms)", 100.0}, {"offline (any time)", INFINITY}};

// Past these a setting is beyond use, however fast: a budget is not met by it. Per section (its
// error metric), with the reason.
struct UseLimit {
  const char* section;
  double error;
  const char* why;
};
constexpr UseLimit kUseLimits[] = {
    {"fog-tables", 0.02, "a fog weight 0.02 off is 5 steps of 8-bit colour"},
    {"fog-conventions", 0.02, "as fog tables"},
    {"fog-height-march", 0.02, "as fog tables"},
    {"lightning-tv", 0.5, "half of every step's choice elsewhere than the reference would put it"},
    {"lightning3d-tv", 0.5, "as lightning-tv"},
    {"lightning-fd", 0.1, "|D - D_ref| 0.1: visibly sparser or bushier"},
    {"lightning3d-fd", 0.1, "as lightning-fd"},
    {"lightning-shape", 3.0, "3 standard errors: a bolt that seeds' noise does not explain"},
    {"tangents", 5.0, "a mean 5 degree tilt shows in normal-mapped highlights"},
    {"thin-film", 2.3, "mean Delta E 2.3, one just-noticeable difference"},
    {"glow-apsf", 0.05, "5 % of the halo's light elsewhere: a visibly different halo"},
    {"render-fog", 2.0, "2 steps of 8-bit colour, a visible band"},
    {"render-lightning", 1.75, "the bound /v1/render states: the core 1.75 px wider than coreWidth"},
    {"render-bubble", 5.0, "mean Delta E 5: the same colours side by side, but a visibly different bubble"},
};
double useLimit(const Section& s) {
  for (const UseLimit& u : kUseLimits)
    if (s.id == u.section) return u.error;
  return INFINITY;
}

// The closest point of a group whose median time fits the budget (ties in error: the faster),
// within the section's limit of use.
const Point* choiceWithin(const Section& s, const std::string& group, double budgetMs) {
  const Point* best = nullptr;
  const double limit = useLimit(s);
  for (const auto& p : s.points)
    if (p.group == group && p.ms > 0 && p.ms <= budgetMs && std::isfinite(p.error) && p.error <= limit &&
        (!best || p.error < best->error || (p.error == best->error && p.ms < best->ms)))
      best = &p;
  return best;
}

// A section's groups in report order.
std::vector<std::string> groupsOf(const Section& s) {
  std::vector<std::string> out;
  for (const auto& p : s.points)
    if (std::find(out.begin(), out.end(), p.group) == out.end()) out.push_back(p.group);
  return out;
}

// The summary at the top: per section and group, its Pareto front of error against time and the choice
// for each budget, all read off the numbers below.
std::string summaryMarkdown(const std::vector<Section>& sections) {
  std::ostringstream md;
  md << "## Summary: what to choose\n\n"
     << "Per section and what a client fixes first (a grid, a fog type, a mesh): the **Pareto front** (no other "
        "setting is as fast and closer to the reference), fastest "
        "first, and the closest setting whose median time fits each budget. Times are per the section's unit; "
        "error 0 is the reference itself. Computed from the tables below by the generator, not written by hand. "
        "A setting beyond its section's limit of use (listed below the table) is never a budget's choice: where "
        "every setting that fits is beyond it, the cell says so.\n\n"
     << "| section | error metric | Pareto front (time, error) |";
  for (const Budget& b : kBudgets) md << " " << b.name << " |";
  md << "\n|---|---|---|";
  for (size_t i = 0; i < std::size(kBudgets); ++i) md << "---|";
  md << "\n";
  for (const Section& s : sections) {
    const std::string unit = s.timeScale == 1000 ? " µs" : " ms";
    auto show = [&](const Point* p) {
      return p->series + " " + p->setting + " (" + fmt(p->ms * s.timeScale) + unit + ", " + fmt(p->error, 2) + ")";
    };
    for (const std::string& group : groupsOf(s)) {
      md << "| " << s.title << (group.empty() ? "" : ": " + group) << " | " << s.errorName << " (time: " << s.timeName
         << ") | ";
      const auto front = paretoFront(s, group);
      for (size_t i = 0; i < front.size(); ++i) md << (i ? " → " : "") << show(front[i]);
      md << " |";
      for (const Budget& b : kBudgets) {
        const Point* c = choiceWithin(s, group, b.ms);
        bool fits = false;  // something fits the time, but none within the limit of use
        for (const auto& p : s.points) fits = fits || (p.group == group && p.ms > 0 && p.ms <= b.ms);
        md << " "
           << (c      ? show(c)
               : fits ? "nothing within use (error ≤ " + fmt(useLimit(s)) + ") fits"
                      : std::string("nothing fits"))
           << " |";
      }
      md << "\n";
    }
  }
  md << "\nLimits of use (error beyond which a setting is no budget's choice):";
  for (const UseLimit& u : kUseLimits) md << " " << u.section << " " << fmt(u.error) << " (" << u.why << ");";
  md << "\n\n";
  return md.str();
}

// A label in lines of about `width` characters (gnuplot's "\n" in a double-quoted string).
std::string wrapped(const std::string& text, size_t width) {
  std::string out;
  size_t line = 0;
  for (size_t i = 0; i < text.size();) {
    size_t end = text.find(' ', i);
    if (end == std::string::npos) end = text.size();
    if (line > 0 && line + (end - i) > width)
      out += "\\n", line = 0;
    else if (line > 0)
      out += ' ', ++line;
    out.append(text, i, end - i);
    line += end - i;
    i = end + 1;
  }
  return out;
}

void plot(const Section& s, const fs::path& dir) {
  std::map<std::string, std::vector<const Point*>> series;
  double floorError = INFINITY;
  for (const auto& p : s.points)
    if (p.ms > 0 && p.error > 0 && std::isfinite(p.error))
      series[p.series].push_back(&p), floorError = std::min(floorError, p.error);
  // Error 0 (a reference, an exact method) has no place on a log axis: drawn at the floor, a
  // decade under the smallest nonzero error, with its own marker.
  std::vector<const Point*> exact;
  for (const auto& p : s.points)
    if (p.ms > 0 && p.error == 0) exact.push_back(&p);
  if (series.empty() && exact.empty()) return;
  if (!std::isfinite(floorError)) floorError = 1;
  const double floorAt = floorError / 10;
  const fs::path data = dir / (s.id + ".dat"), script = dir / (s.id + ".gp");
  std::ofstream d(data);
  for (const auto& [name, pts] : series) {
    d << "# " << name << "\n";
    for (const Point* p : pts) d << p->ms * s.timeScale << " " << p->error << "\n";
    d << "\n\n";
  }
  for (const Point* p : exact)
    d << "# error 0: " << p->series << " " << p->setting << "\n" << p->ms * s.timeScale << " " << floorAt << "\n\n\n";
  d.close();
  std::ofstream g(script);
  const size_t curves = series.size() + exact.size();
  // Many curves or long names: the key goes below the plot in as many columns (up to 3) as the
  // longest title lets fit (gnuplot reserves about 9 px a character at this font, and the line
  // sample), and the picture grows to hold its rows; the plot keeps its height.
  size_t longest = 0;
  for (const auto& [name, pts] : series) longest = std::max(longest, name.size());
  for (const Point* p : exact) longest = std::max(longest, p->series.size() + p->setting.size() + 24);
  const bool many = curves > 10 || longest > 32;
  const int width = many ? 1500 : 800;
  const size_t columns = std::clamp<size_t>(size_t(width) / (longest * 9 + 80), 1, 3);
  const size_t rows = (curves + columns - 1) / columns;
  const int height = many ? 560 + 18 * int(rows) : 520;
  g << "set terminal pngcairo noenhanced size " << width << "," << height << " font 'sans,10'\n"
    << "set output '" << (dir / (s.id + ".png")).string() << "'\n"
    << "set title \"" << s.title << "\"\n"
    << "set logscale xy\nset grid\n"
    << (many ? "set key outside below maxcols " + std::to_string(columns) + " maxrows " + std::to_string(rows) + "\n"
             : std::string("set key outside right top\n"))
    << "set xlabel \"" << s.timeName << ", log scale\"\nset ylabel \"" << wrapped(s.errorName + ", log scale", 40)
    << "\"\n"
    << "set format y '%.0e'\n";
  if (!exact.empty())
    g << "set arrow from graph 0, first " << floorAt << " to graph 1, first " << floorAt
      << " nohead dt 3 lc rgb 'gray'\n";
  g << "plot ";
  int i = 0;
  for (const auto& [name, pts] : series) {
    // gnuplot cycles 8 colours: past them, another point shape and dashes tell curves apart.
    const int round = i / 8;
    g << (i ? ", " : "") << "'" << data.string() << "' index " << i << " with linespoints lc " << (i % 8 + 1) << " pt "
      << (round == 0   ? 7
          : round == 1 ? 5
                       : 9)
      << " dt " << (round + 1) << " ps 0.8 title '" << name << "'";
    ++i;
  }
  for (size_t k = 0; k < exact.size(); ++k, ++i)
    g << (i ? ", " : "") << "'" << data.string() << "' index " << i << " with points lc " << (i % 8 + 1)
      << " pt 12 ps 2 title '" << exact[k]->series << " " << exact[k]->setting << " (error 0, at the floor)'";
  g << "\n";
  g.close();
  const std::string cmd = "gnuplot '" + script.string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "error_report: gnuplot failed for %s\n", s.id.c_str());
  fs::remove(data);
  fs::remove(script);
}

// A sheet as one PNG: panels of bolts, white main channels and blue branches on black, y down.
void drawSheet(const Sheet& sheet, const fs::path& dir) {
  const fs::path data = dir / (sheet.id + ".dat"), script = dir / (sheet.id + ".gp");
  std::ofstream d(data);
  auto block = [&](const std::vector<std::array<float, 4>>& segments) {
    for (const auto& e : segments) d << e[0] << " " << e[1] << " " << e[2] - e[0] << " " << e[3] - e[1] << "\n";
    if (segments.empty()) d << "0 0 0 0\n";  // every index exists: gnuplot counts blank-line pairs
    d << "\n\n";
  };
  for (size_t i = 0; i < sheet.titles.size(); ++i) block(sheet.branches[i]), block(sheet.main[i]);
  d.close();
  const int rows = int((sheet.titles.size() + size_t(sheet.columns) - 1) / size_t(sheet.columns));
  const double aspect = double(sheet.height) / double(sheet.width);
  const int panel = 960 / sheet.columns, w = panel * sheet.columns, h = int(panel * aspect * rows) + 40 * rows + 30;
  std::ofstream g(script);
  g << "set terminal pngcairo noenhanced background rgb 'black' size " << w << "," << h << " font 'sans,9'\n"
    << "set output '" << (dir / (sheet.id + ".png")).string() << "'\n"
    << "set multiplot layout " << rows << "," << sheet.columns << " title \"" << sheet.caption << "\" tc rgb 'white'\n"
    << "unset key\nunset tics\nset border lc rgb '#404040'\nset size ratio -1\nset lmargin 0.5\nset rmargin 0.5\n"
    << "set xrange [0:" << sheet.width << "]\nset yrange [" << sheet.height << ":0]\n";
  for (const auto& o : sheet.obstacles)  // objects stay for every panel of the multiplot
    g << "set object rect from " << o[0] << "," << o[1] << " to " << o[0] + o[2] << "," << o[1] + o[3]
      << " fc rgb '#505050' fs solid noborder behind\n";
  for (size_t i = 0; i < sheet.titles.size(); ++i)
    g << "set title '" << sheet.titles[i] << "' tc rgb 'white'\n"
      << "plot '" << data.string() << "' index " << 2 * i << " with vectors nohead lc rgb '#7fa8ff' lw 1, '' index "
      << 2 * i + 1 << " with vectors nohead lc rgb 'white' lw 2\n";
  g << "unset multiplot\n";
  g.close();
  const std::string cmd = "gnuplot '" + script.string() + "'";
  if (std::system(cmd.c_str()) != 0) std::fprintf(stderr, "error_report: gnuplot failed for %s\n", sheet.id.c_str());
  fs::remove(data);
  fs::remove(script);
}

// One section's Markdown (from "## title" to its conclusion) and its JSON entry.
std::string sectionMarkdown(const Section& s, bool withPlot, const std::vector<Sheet>& sheets, json& entry) {
  std::ostringstream md;
  md << "## " << s.title << "\n\nReference: " << s.reference << ".\n\n";
  if (withPlot) md << "![" << s.title << "](error-vs-time/" << s.id << ".png)\n\n";
  md << "| method | " << s.settingName << " | " << s.timeName << " [interquartile range] | " << s.errorName << " |"
     << (s.noteName.empty() ? "" : " " + s.noteName + " |") << "\n|---|---|---|---|"
     << (s.noteName.empty() ? "" : "---|") << "\n";
  json pts = json::array();
  for (const Point& p : s.points) {
    md << "| " << p.series << " | " << p.setting << " | " << timeText(s, p) << " | " << fmt(p.error) << " |"
       << (s.noteName.empty() ? "" : " " + p.note + " |") << "\n";
    pts.push_back({{"series", p.series},
                   {"setting", p.setting},
                   {"ms", p.ms},
                   {"msQ1", p.q1},
                   {"msQ3", p.q3},
                   {"repeats", p.repeats},
                   {"runMedians", p.runMedians},
                   {"error", std::isfinite(p.error) ? json(p.error) : json()},
                   {"note", p.note}});
  }
  md << "\n**Conclusion.** " << s.conclusion << "\n\n";
  if (!s.pictures.empty()) {
    std::string head = "|", rule = "|", row = "|";
    for (const auto& [caption, file] : s.pictures)
      head += " " + caption + " |", rule += "---|", row += " ![](error-vs-time/" + file + ") |";
    md << head << "\n" << rule << "\n" << row << "\n\n";
  }
  for (const Sheet& sheet : sheets)
    if (withPlot && sheet.section == s.id) md << "![" << sheet.caption << "](error-vs-time/" << sheet.id << ".png)\n\n";
  json front = json::object(), budgets = json::object();
  for (const std::string& group : groupsOf(s)) {
    for (const Point* p : paretoFront(s, group)) front[group].push_back(p->series + " " + p->setting);
    for (const Budget& b : kBudgets) {
      const Point* c = choiceWithin(s, group, b.ms);
      budgets[group][b.name] = c ? json(c->series + " " + c->setting) : json();
    }
  }
  entry = {{"title", s.title},  {"errorMetric", s.errorName}, {"reference", s.reference},
           {"points", pts},     {"conclusion", s.conclusion}, {"pareto", front},
           {"budgets", budgets}};
  return md.str();
}

// Writes the whole report from this run's sections.
void write(const std::vector<Section>& sections, const std::vector<Sheet>& sheets, const fs::path& out, bool quick,
           bool plots, const std::string& stamp) {
  fs::create_directories(out / "error-vs-time");
  json j = json::object();
  std::string md =
      std::string("# Error against run time\n\n") +
      (stamp.empty() ? "Generated by `build/bench/error_report" + std::string(quick ? " --quick" : "") + "`." : stamp) +
      " One run: every number below comes from it. Errors are measured once, on the configuration that is "
      "timed, against each section's reference. Times come afterwards from " +
      std::to_string(quick ? 2 : kTimingProcesses) +
      " separate processes, run one after another, each timing every row in turn: a time is the median over "
      "all their repeats (or, for bolts, over seeds; every process grows every seed) with the interquartile "
      "range in brackets and each process's own median after it; two times whose ranges overlap are a tie.\n\n";
  md += summaryMarkdown(sections);
  j["stamp"] = stamp;
  for (const Section& s : sections) {
    if (plots) plot(s, out / "error-vs-time");
    for (const Sheet& sheet : sheets)
      if (plots && sheet.section == s.id) drawSheet(sheet, out / "error-vs-time");
    md += sectionMarkdown(s, fs::exists(out / "error-vs-time" / (s.id + ".png")), sheets, j[s.id]);
  }
  std::ofstream(out / "error-vs-time.md") << md;
  std::ofstream(out / "error-vs-time.json") << j.dump(1) << "\n";
}

}  // namespace

int main(int argc, char** argv) {
  bool quick = false, plots = true;
  fs::path out = "docs";
  std::string stamp;
  for (int i = 1; i < argc; ++i) {
    std::string a = argv[i];
    if (a == "--quick")
      quick = true;
    else if (a == "--no-plots")
      plots = false;
    else if (a == "--out" && i + 1 < argc)
      out = argv[++i];
    else if (a == "--stamp" && i + 1 < argc)
      stamp = argv[++i];
    else {
      std::fprintf(stderr, "usage: error_report [--quick] [--out DIR] [--no-plots] [--stamp TEXT]\n");
      return 2;
    }
  }
  if (plots && std::system("gnuplot --version >/dev/null 2>&1") != 0) {
    std::fprintf(
        stderr,
        "error_report: gnuplot not found (Debian: gnuplot-nox; scripts/setup.sh installs it), or pass --no-plots\n");
    return 2;
  }
  std::vector<Section> sections;
  effects::Stopwatch total;
  auto step = [&](const char* what) { std::fprintf(stderr, "[%6.1f s] %s\n", total.ms() / 1000, what); };
  {
    step("lightning");
    Section tv, fd;
    lightning(quick, tv, fd);
    sections.insert(sections.end(), {tv, fd});
  }
  step("lightning shapes");
  sections.emplace_back();
  std::vector<Sheet> sheets;
  lightningShape(quick, sections.back(), sheets);
  {
    step("lightning in 3-D");
    Section tv, fd;
    lightning3d(quick, tv, fd);
    sections.insert(sections.end(), {tv, fd});
  }
  {
    step("fog");
    Section tables, march, conventions;
    fog(quick, tables, march);
    fogConventions(quick, conventions);
    sections.insert(sections.end(), {tables, march, conventions});
  }
  step("tangents");
  sections.emplace_back();
  tangents(quick, sections.back());
  step("thin film");
  sections.emplace_back();
  thinFilm(quick, sections.back());
  step("glow");
  sections.emplace_back();
  glowKernels(quick, sections.back());
  sections.emplace_back();
  renderPreviewTimes(quick, sections.back());
  sections.emplace_back();
  fogPreviewTimes(quick, sections.back());
  sections.emplace_back();
  lightningPreviewTimes(quick, sections.back());
  step("timing");
  if (!timings.run(quick ? 2 : kTimingProcesses)) return 1;  // quick: the same path, cheaper
  for (Section& s : sections)
    for (Point& p : s.points) {
      if (p.ticket == bench::Timings::kNone) continue;
      std::vector<double> t = timings.times(p.ticket);
      for (double& x : t) x *= p.timeFactor;
      const Timing spread = spreadOf(t);
      p.ms = spread.median, p.q1 = spread.q1, p.q3 = spread.q3, p.repeats = spread.n;
      for (double m : timings.runMedians(p.ticket)) p.runMedians.push_back(m * p.timeFactor);
    }
  step("render previews");
  auto renderer = rd::Renderer::create();  // after the timing processes: they cannot share it
  if (!renderer.ok()) return std::fprintf(stderr, "error_report: %s\n", renderer.error().message.c_str()), 1;
  if (!renderPreviewErrors(quick, sections[sections.size() - 3], *renderer.value(), out / "error-vs-time") ||
      !fogPreviewErrors(quick, sections[sections.size() - 2], *renderer.value()) ||
      !lightningPreviewErrors(quick, sections.back(), *renderer.value()))
    return 1;
  conclude(sections);
  write(sections, sheets, out, quick, plots, stamp);
  step(("wrote " + (out / "error-vs-time.md").string()).c_str());
  return 0;
}
