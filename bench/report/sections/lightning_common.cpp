// The lightning sections' shared parts (lightning_common.h).
#include "lightning_common.h"

#include <cstdio>

#include "fixtures.h"

namespace report {

lt::Params layoutOf(int n, bool volume) { return volume ? fixtures::volumeLayout(n) : fixtures::lightningLayout(n); }

json gridRequest(int n, int hood, bool volume) {
  json grid = {{"width", n}, {"height", n}};
  if (volume) grid["depth"] = n;
  return {{"grid", grid}, {"neighbourhood", hood}};
}

std::vector<LightningSetting> lightningSettings(bool quick, int n, int hood, bool volume) {
  const auto layout = [&] {
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
                      {{"method", "fast"}}, calibrated});
  for (int life : {2, 4, 8, 0}) {  // variant paper has lifetime 4; the others override it
    lt::Params p = layout();
    lt::usePaperConstants(p);
    p.lifetime = life;
    json request = {{"method", "fast"}, {"variant", "paper"}};
    if (life != lt::kPaperLifetime) request["lifetime"] = life;
    settings.push_back(
        {"fast paper", life == lt::kPaperLifetime ? "variant paper: lifetime 4" : "lifetime " + (life ? std::to_string(life) : std::string("inf")),
         request, p});
  }
  for (double growth : {1.5, 1.25, 1.1, 1.0}) {  // eqn 8's base, candidates never expiring
    lt::Params p = layout();
    p.axisGrowth = growth;
    p.lifetime = 0;
    settings.push_back({"fast axisGrowth", "axisGrowth " + fmt(growth, 3),
                        {{"method", "fast"}, {"axisGrowth", growth}, {"lifetime", 0}}, p});
  }
  if (!volume && (n <= 128 || hood == 8)) {  // charges is O(cells x candidates): ~10 s a bolt at 256^2
    lt::Params c = layout();
    c.method = lt::Method::kCharges;
    settings.push_back({"charges calibrated", "default: power " + fmt(lt::calibratedChargesEta(c), 3),
                        {{"method", "charges"}}, c});
    lt::usePaperConstants(c);  // Kim et al.'s parameter at DBM's eta: space-filling
    settings.push_back({"charges paper", "variant paper: power " + fmt(c.eta, 3), {{"method", "charges"}, {"variant", "paper"}}, c});
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
    settings.push_back({"dbm-capacitance", "default: exact, MGPCG at tol 1e-6 past its limit", {{"method", "dbm"}}, p});
  }
  for (lt::Solver solver : {lt::Solver::kMgpcg, lt::Solver::kCg}) {
    if (solver == lt::Solver::kCg && (quick || volume || n > 64)) continue;
    for (double tol : tolerances) {
      lt::Params p = layout();
      p.method = lt::Method::kDbm;
      p.solver = solver;
      p.tolerance = tol;
      settings.push_back({std::string("dbm-") + lt::toString(solver), "tol " + fmt(tol, 1),
                          {{"method", "dbm"}, {"solver", lt::toString(solver)}, {"tolerance", tol}}, p});
    }
  }
  return settings;
}

double dimensionOf(const lt::Bolt& b, int n) {
  std::vector<lt::Cell> cells;
  for (const auto& node : b.nodes) cells.push_back(node.cell);
  return b.depth ? lt::fractalDimension(cells, n, n, n) : lt::fractalDimension(cells, n, n);
}

size_t timeBolts(Run& run, const std::string& name, lt::Params p, int seeds) {
  return run.time(name, [p, seeds]() mutable {
    std::vector<double> t;
    for (int seed = 1; seed <= seeds; ++seed) {
      p.seed = uint64_t(seed);
      if (auto b = lt::grow(p); b.ok()) t.push_back(b.value().stats.elapsedMs);
    }
    return t;
  });
}

Metric tvMetric() {
  return {"tv", "TV", "mean total-variation distance per step from the converged distribution", 0.5,
          "half of every step's choice elsewhere than the reference would put it"};
}

Metric fdMetric() {
  return {"fd", "ΔD", "abs(mean D − D_ref), box-counting dimension over seeds", 0.1, "|D − D_ref| 0.1: visibly sparser or bushier"};
}

void lightningRows(Run& run, int n, int hood, bool volume) {
  const int seeds = run.quick ? 3 : 10;
  const std::string grid = std::to_string(n) + (volume ? "³, " : "², ") + std::to_string(hood) + "-nbhd";
  std::fprintf(stderr, "           %s\n", grid.c_str());
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
  for (const auto& s : lightningSettings(run.quick, n, hood, volume)) {
    std::vector<double> dims, tvs;
    for (int seed = 1; seed <= seeds; ++seed) {
      lt::Params p = s.params;
      p.seed = uint64_t(seed);
      auto b = lt::grow(p);
      if (!b.ok()) continue;
      dims.push_back(dimensionOf(b.value(), n));
      if (n > 128) continue;  // the reference solve every step costs seconds per 256^2 bolt
      p.measureError = true;
      auto e = lt::grow(p);
      if (e.ok()) tvs.push_back(e.value().stats.error.value_or(0));
    }
    const auto [mean, sd] = meanSd(dims);
    Row r;
    r.series = s.series + " " + grid;  // one curve per method, grid and neighbourhood
    r.setting = s.setting;
    r.group = grid;
    r.request = s.request;
    r.ticket = timeBolts(run, r.series + " " + s.setting, s.params, seeds);  // over seeds: each a different bolt
    r.errors["fd"] = std::abs(mean - dRef);
    r.note = "D " + fmt(mean, 3) + " ± " + fmt(sd, 2);
    if (!tvs.empty()) {
      const auto [tvMean, tvSd] = meanSd(tvs);
      r.errors["tv"] = tvMean;
      r.note += "; TV ± " + fmt(tvSd, 2);
    }
    r.note += " (" + std::to_string(dims.size()) + " seeds)";
    run.rows.push_back(r);
  }
  Row ref;
  ref.series = "dbm reference " + grid;
  ref.setting = "D_ref";
  ref.group = grid;
  ref.request = {{"method", "dbm"}, {"tolerance", 1e-8}};
  ref.errors["fd"] = 0;
  ref.note = "D " + fmt(dRef, 3) + " ± " + fmt(dRefSd, 2) + " (" + std::to_string(refD.size()) + " seeds)";
  run.rows.push_back(ref);
}

std::string lightningConclusion(const Run& run) {
  std::string c;
  auto show = [](const Row& r, const std::string& id) {
    return r.series + " " + r.setting + " (" + fmt(r.ms) + " ms, " + id + " " + fmt(errorOf(r, id)) + ")";
  };
  const Row* good = fastestWithin(run, "tv", 0.05);
  const Row* fast = fastestWithin(run, "tv", 1.0, "fast paper");
  if (good && fast)
    c += "Fastest setting within a TV distance of 0.05 of the converged distribution: " + show(*good, "tv") +
         "; the paper's fast method costs " + fmt(fast->ms) + " ms but its distribution is far from DBM's (TV " +
         fmt(errorOf(*fast, "tv")) + "): it is a different growth law, not an approximation that converges. ";
  const Row* best = nullptr;
  for (const Row& r : run.rows)
    if (r.ms > 0 && r.series.rfind("dbm", 0) != 0 && (!best || errorOf(r, "fd") < errorOf(*best, "fd"))) best = &r;
  if (best) c += "Closest to DBM's dimension without a linear solve: " + show(*best, "fd") + ".";
  c += " The calibrated default's |D − D_ref| per grid (variant paper's in brackets):";
  for (const Row& r : run.rows) {
    if (r.series.rfind("fast calibrated", 0) != 0) continue;
    c += " " + r.group + " " + fmt(errorOf(r, "fd"), 2);
    for (const Row& q : run.rows)
      if (q.series == "fast paper " + r.group && q.setting.rfind("variant paper", 0) == 0)
        c += " (" + fmt(errorOf(q, "fd"), 2) + ")";
    c += ";";
  }
  // Per DBM curve: the loosest tolerance from which |D - D_ref| stays within 0.03.
  std::map<std::string, std::string> settles;
  for (const Row& r : run.rows) {
    if (r.series.rfind("dbm-", 0) != 0) continue;
    if (errorOf(r, "fd") > 0.03)
      settles[r.series] = "";
    else if (settles[r.series].empty())
      settles[r.series] = r.setting;
  }
  c += " DBM's dimension stays within 0.03 of D_ref from";
  for (const auto& [series, setting] : settles) c += " " + series + ": " + (setting.empty() ? "never" : setting) + ";";
  c += " looser solves grow visibly different (bushier) bolts.";
  return c;
}

}  // namespace report
