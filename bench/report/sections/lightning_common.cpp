// The lightning sections' shared parts (lightning_common.h).
#include "lightning_common.h"

#include <algorithm>
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
  if (!volume) {
    lt::Params c = layout();
    c.method = lt::Method::kCharges;
    settings.push_back({"charges calibrated", "default: power " + fmt(lt::calibratedChargesEta(c), 3),
                        {{"method", "charges"}}, c});
    // Kim et al.'s parameter at DBM's eta fills space (D 1.7 at 64^2, 1.8 at 128^2, 1.9 at 256^2
    // when last measured) and costs 20x, 40x and 140x the calibrated power (40 ms, 0.67 s and
    // 12.8 s a bolt): shown where it is cheap.
    lt::usePaperConstants(c);
    if (n <= 64)
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

size_t timeBolts(Run& run, const std::string& name, lt::Params p, int seeds, double boltMs) {
  const int k = boltMs > 0 ? std::clamp(int(std::min(kBoltTimingMs / boltMs, 1e6)), 1, seeds) : seeds;
  return run.time(name, [p, seeds, k](int process) mutable {
    std::vector<double> t;
    for (int i = 0; i < k; ++i) {
      p.seed = uint64_t((k == seeds ? i : process * k + i) % seeds + 1);
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
  // D over `seeds`; TV over the first tvSeeds: all of them at 64^2, 3 past it, where its
  // reference solve every step costs 10 to 100 times the bolt (its standard error then reaches
  // 0.07 where seeds spread by 0.12), and none past 128^2 (seconds per 256^2 bolt).
  const int seeds = run.quick ? 3 : 10, tvSeeds = n <= 64 && !volume ? seeds : std::min(seeds, 3);
  const bool withTv = n <= 128;
  const std::string grid = std::to_string(n) + (volume ? "³, " : "², ") + std::to_string(hood) + "-nbhd";
  std::fprintf(stderr, "           %s\n", grid.c_str());
  const auto settings = lightningSettings(run.quick, n, hood, volume);
  std::vector<lt::Params> params;  // every setting's, then the reference's
  for (const auto& s : settings) params.push_back(s.params);
  {
    lt::Params p = layoutOf(n, volume);
    p.neighbourhood = hood;
    p.method = lt::Method::kDbm;
    p.tolerance = 1e-8;
    params.push_back(p);
  }
  // Every bolt grown at once on the machine's cores: (params, seed) -> D, its time, its TV.
  const size_t perParams = size_t(seeds + (withTv ? tvSeeds : 0));
  std::vector<double> dims(params.size() * size_t(seeds), NAN), ms(dims.size(), NAN),
      tvs(params.size() * size_t(tvSeeds), NAN);
  onEveryCore(params.size() * perParams, [&](size_t task) {
    const size_t i = task / perParams, j = task % perParams;
    lt::Params p = params[i];
    if (j < size_t(seeds)) {
      p.seed = j + 1;
      if (auto b = lt::grow(p); b.ok()) dims[i * size_t(seeds) + j] = dimensionOf(b.value(), n), ms[i * size_t(seeds) + j] = b.value().stats.elapsedMs;
    } else if (i < settings.size()) {  // the reference's own TV is not measured
      p.seed = j - size_t(seeds) + 1;
      p.measureError = true;
      if (auto e = lt::grow(p); e.ok()) tvs[i * size_t(tvSeeds) + j - size_t(seeds)] = e.value().stats.error.value_or(0);
    }
  });
  const auto of = [](const std::vector<double>& v, size_t i, int count) {
    std::vector<double> out;
    for (size_t j = i * size_t(count); j < (i + 1) * size_t(count); ++j)
      if (!std::isnan(v[j])) out.push_back(v[j]);
    return out;
  };
  const std::vector<double> refD = of(dims, settings.size(), seeds);
  const auto [dRef, dRefSd] = meanSd(refD);
  for (size_t i = 0; i < settings.size(); ++i) {
    const auto& s = settings[i];
    const std::vector<double> d = of(dims, i, seeds), tv = of(tvs, i, tvSeeds);
    const auto [mean, sd] = meanSd(d);
    Row r;
    r.series = s.series + " " + grid;  // one curve per method, grid and neighbourhood
    r.setting = s.setting;
    r.group = grid;
    r.request = s.request;
    r.ticket = timeBolts(run, r.series + " " + s.setting, s.params, seeds, quantile(of(ms, i, seeds), 0.5));
    r.errors["fd"] = std::abs(mean - dRef);
    r.note = "D " + fmt(mean, 3) + " ± " + fmt(sd, 2);
    if (!tv.empty()) {
      const auto [tvMean, tvSd] = meanSd(tv);
      r.errors["tv"] = tvMean;
      r.note += "; TV ± " + fmt(tvSd, 2);
    }
    r.note += " (" + std::to_string(d.size()) + " seeds";
    if (!tv.empty() && tv.size() != d.size()) r.note += ", TV " + std::to_string(tv.size());
    r.note += ")";
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
