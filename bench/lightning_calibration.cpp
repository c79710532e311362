// How far the fast method's bolts are from DBM's, in the statistics a player sees: box-counting
// dimension D, cells, branch tips (cells nothing grew from). Start top-centre, target
// bottom-centre of an N x N grid, no obstacles; every row is over `--seeds` bolts (DBM:
// `--dbm-seeds`). For the fast method each `--axis` value (eqn 8's base per cell) and each
// `--lifetime` is a row, so a scan shows which setting meets DBM at each grid and eta.
//
//   lightning_calibration [--grid N]... [--eta E]... [--axis A]... [--lifetime L]...
//                         [--seeds S] [--dbm-seeds S] [--dbm-first-seed F] [--neighbourhood 4|8]
//                         [--fit] [--charges-eta E]... [--screening S]... [--volume]
// --dbm-first-seed: DBM's bolts are seeds F ... F+S-1 (default 1), so slow references can be
// grown a few seeds a run and pooled by hand.
// Knobs not given (--lifetime; the radius unless --radius) take the calibrated value of each
// row's grid and eta, as the server's default does.
// --volume: N x N x N grids (neighbourhood 26 unless given; 6 is the other 3-D one).
// --screening: the exponent of eqn 6's N (1 in the paper), one row (or fit) per value.
// --charges-eta: rows for the charges method (Kim et al. 2007) with their potential raised to
// these powers (Params::chargesEta), beside DBM's row at each --eta: which power gives DBM's
// statistics; 0 is the calibrated power for the row's grid and eta (calibratedChargesEta).
// --fit: instead of the --axis rows, the base per cell at which the fast method's median
// cells meet DBM's (bisection), and the statistics it gives.
// Output: a markdown table, one row per (grid, eta, method, setting): mean +- sd of D,
// medians of cells and tips, and the mean milliseconds per bolt.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <effects/lightning.h>

namespace lt = effects::lightning;

namespace {

struct Sample {
  double d = 0, cells = 0, tips = 0, ms = 0;
};

Sample measure(const lt::Params& p) {
  const auto t0 = std::chrono::steady_clock::now();
  auto r = lt::grow(p);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  if (!r.ok()) {
    std::fprintf(stderr, "grow failed: %s\n", r.error().message.c_str());
    std::exit(1);
  }
  const lt::BoltShape s = lt::shapeOf(r.value(), p.width, p.height, p.depth);
  return {s.dimension, s.cells, s.tips, ms};
}

double median(std::vector<double> v) {
  if (v.empty()) return std::nan("");
  std::sort(v.begin(), v.end());
  return v.size() % 2 ? v[v.size() / 2] : 0.5 * (v[v.size() / 2 - 1] + v[v.size() / 2]);
}

// Prints one table row over `seeds` bolts (seeds firstSeed, firstSeed + 1, ...); returns their
// median cells.
double row(const std::string& grid, double eta, const char* method, const std::string& setting, const lt::Params& base, int seeds,
           int firstSeed = 1) {
  if (seeds <= 0) return std::nan("");  // --seeds 0: DBM's rows alone
  std::vector<double> d, cells, tips;
  double ms = 0;
  for (int s = firstSeed; s < firstSeed + seeds; ++s) {
    lt::Params p = base;
    p.seed = uint64_t(s);
    const Sample x = measure(p);
    d.push_back(x.d);
    cells.push_back(x.cells);
    tips.push_back(x.tips);
    ms += x.ms;
  }
  double mean = 0, var = 0;
  for (double v : d) mean += v / double(d.size());
  for (double v : d) var += (v - mean) * (v - mean) / std::max<double>(1, double(d.size()) - 1);
  std::printf("| %s | %g | %s | %s | %.3f ± %.3f | %.0f | %.0f | %.2f |\n", grid.c_str(), eta, method, setting.c_str(), mean,
              std::sqrt(var), median(cells), median(tips), ms / seeds);
  std::fflush(stdout);
  return median(cells);
}

// Median cells of `seeds` fast bolts with eqn 8's base `axis`.
double medianCells(lt::Params p, double axis, int seeds) {
  std::vector<double> cells;
  p.axisGrowth = axis;
  for (int s = 1; s <= seeds; ++s) {
    p.seed = uint64_t(1000 + s);  // other seeds than the rows print
    cells.push_back(measure(p).cells);
  }
  return median(cells);
}

// The base per cell at which the fast method's median cells meet DBM's: bisection on
// ln(axis) in [0, ln 2] (cells fall as the base grows).
double fitAxis(const lt::Params& base, double dbmCells, int seeds) {
  double lo = 0, hi = std::log(2.0);
  for (int i = 0; i < 10; ++i) {
    const double mid = 0.5 * (lo + hi);
    (medianCells(base, std::exp(mid), seeds) > dbmCells ? lo : hi) = mid;
  }
  return std::exp(0.5 * (lo + hi));
}

// ", screening s" where it is not eqn 6's 1.
std::string screeningNote(double s) {
  if (s == 1.0) return "";
  char note[32];
  std::snprintf(note, sizeof note, ", screening %g", s);
  return note;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<int> grids;
  std::vector<double> etas, axes, chargesEtas, screenings;
  std::vector<int> lifetimes, radii;
  int seeds = 20, dbmSeeds = 10, dbmFirstSeed = 1, neighbourhood = 0;  // 0: 8 in 2-D, 26 in 3-D
  bool fit = false, volume = false;
  for (int i = 1; i < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--fit" || flag == "--volume") {
      (flag == "--fit" ? fit : volume) = true;
      --i;
      continue;
    }
    if (i + 1 >= argc) break;
    const char* v = argv[i + 1];
    if (flag == "--grid")
      grids.push_back(std::atoi(v));
    else if (flag == "--eta")
      etas.push_back(std::atof(v));
    else if (flag == "--axis")
      axes.push_back(std::atof(v));
    else if (flag == "--screening")
      screenings.push_back(std::atof(v));
    else if (flag == "--lifetime")
      lifetimes.push_back(std::atoi(v));
    else if (flag == "--radius")
      radii.push_back(std::atoi(v));
    else if (flag == "--seeds")
      seeds = std::atoi(v);
    else if (flag == "--dbm-seeds")
      dbmSeeds = std::atoi(v);
    else if (flag == "--dbm-first-seed")
      dbmFirstSeed = std::max(1, std::atoi(v));
    else if (flag == "--charges-eta")
      chargesEtas.push_back(std::atof(v));
    else if (flag == "--neighbourhood")
      neighbourhood = std::atoi(v);
    else {
      std::fprintf(stderr, "unknown flag %s\n", argv[i]);
      return 2;
    }
  }
  if (grids.empty()) grids = {64, 128};
  if (etas.empty()) etas = {1, 2, 3};
  const bool calibrated = axes.empty();  // each row at calibratedAxisGrowth() of its grid and eta
  const bool calibratedLifetime = lifetimes.empty();  // each row at calibratedLifetime() of its grid and eta
  if (screenings.empty()) screenings = {lt::Params{}.screening};
  if (radii.empty()) radii = {lt::Params{}.screeningRadius};
  std::printf("| grid | eta | method | setting | D | cells (median) | tips (median) | ms/bolt |\n");
  std::printf("|---|---|---|---|---|---|---|---|\n");
  for (int n : grids)
    for (double eta : etas) {
      const std::string grid = std::to_string(n) + (volume ? "³" : "");
      lt::Params base;
      base.width = base.height = n;
      base.start = {n / 2, 0};
      base.targets = {{n / 2, n - 1}};
      if (volume) {  // n^3, start at the top face's centre, target at the bottom face's
        base.depth = n;
        base.start.z = base.targets[0].z = n / 2;
      }
      base.eta = eta;
      base.neighbourhood = neighbourhood ? neighbourhood : volume ? 26 : 8;
      if (calibratedLifetime) lifetimes = {lt::calibratedLifetime(base)};
      if (dbmSeeds > 0) {
        lt::Params p = base;
        p.method = lt::Method::kDbm;
        // The default solver: exact (capacitance) while its fixed cells allow, then MGPCG.
        const double dbmCells = row(grid, eta, "dbm", std::string(lt::toString(p.solver)) + " (default)", p, dbmSeeds, dbmFirstSeed);
        if (fit) {
          for (double sc : screenings) {
            if (seeds <= 0) break;
            lt::Params f = base;
            f.lifetime = lifetimes.front();
            f.screening = sc;
            const double axis = fitAxis(f, dbmCells, seeds);
            f.axisGrowth = axis;
            char setting[128];
            std::snprintf(setting, sizeof setting, "fitted axis %.4f (ln %.4f), lifetime %d%s", axis, std::log(axis),
                          f.lifetime, screeningNote(sc).c_str());
            row(grid, eta, "fast", setting, f, seeds);
          }
          continue;
        }
      }
      for (double ce : chargesEtas) {
        lt::Params p = base;
        p.method = lt::Method::kCharges;
        p.chargesEta = ce;
        char setting[64];
        if (ce > 0)
          std::snprintf(setting, sizeof setting, "charges eta %g", ce);
        else
          std::snprintf(setting, sizeof setting, "charges calibrated (power %.2f)", lt::calibratedChargesEta(p));
        row(grid, eta, "charges", setting, p, seeds);
      }
      if (!chargesEtas.empty()) continue;
      if (calibrated) axes = {lt::calibratedAxisGrowth(base)};
      for (double a : axes)
        for (int l : lifetimes)
          for (double sc : screenings)
            for (int rad : radii) {
              lt::Params p = base;
              p.axisGrowth = a;
              p.lifetime = l;
              p.screening = sc;
              p.screeningRadius = rad;
              char setting[128];
              const int r = lt::screeningRadius(p);
              std::snprintf(setting, sizeof setting, "axis %g, lifetime %d%s%s", a, l, screeningNote(sc).c_str(),
                            r > 1 ? (", radius " + std::to_string(r)).c_str() : "");
              row(grid, eta, "fast", setting, p, seeds);
            }
    }
}
