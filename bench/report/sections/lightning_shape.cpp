// What a player sees, against exact DBM over seeds: cells, tips and D (lt::shapeDistance: each
// difference in standard errors of the two means), in the geometries games use: the open
// layout the calibration grows, a point target off-axis, the ground (a target region: every
// bottom cell), a wall (example 04), a wide grid, 3-D towards a ground plane, and a 3-wide
// channel whose field ahead of the bolt falls far below double's range (DeepField). A bolt
// that fills its channel scores in the hundreds. Each layout also gets a sheet: the first
// seeds' DBM bolts above the calibrated fast method's.
#include <optional>

#include "lightning_common.h"
#include "sections.h"

namespace report {

namespace {

struct Layout {
  std::string name, id, ask;
  lt::Params params;
  json fixed;               // the request fields of the layout
  bool tolerances = false;  // also DBM with MGPCG at loose tolerances
};

// Every bottom cell (3-D: the bottom layer) a target.
lt::Params grounded(lt::Params p) {
  p.targets.clear();
  p.targetRegion.assign(size_t(p.width) * size_t(p.height) * size_t(std::max(p.depth, 1)), 0);
  for (int z = 0; z < std::max(p.depth, 1); ++z)
    for (int x = 0; x < p.width; ++x)
      p.targetRegion[(size_t(z) * size_t(p.height) + size_t(p.height - 1)) * size_t(p.width) + size_t(x)] = 1;
  lt::calibrate(p);
  return p;
}

json pointRequest(const lt::Params& p) {
  json grid = {{"width", p.width}, {"height", p.height}};
  if (p.depth) grid["depth"] = p.depth;
  json r = {{"grid", grid}, {"start", {p.start.x, p.start.y}}};
  if (p.depth) r["start"].push_back(p.start.z);
  if (p.targetRegion.empty()) r["targets"] = {{p.targets[0].x, p.targets[0].y}};
  else r["targetRegion"] = "the bottom row" + std::string(p.depth ? " (layer)" : "");
  return r;
}

std::vector<Layout> layouts(bool quick) {
  std::vector<Layout> out;
  for (int n : quick ? std::vector<int>{32} : std::vector<int>{64, 128}) {
    const lt::Params p = layoutOf(n, false);
    out.push_back({std::to_string(n) + "² open", "open-" + std::to_string(n), "a bolt on " + std::to_string(n) + "² to a point",
                   p, gridRequest(n, 8, false), true});
  }
  const int n = quick ? 32 : 128;
  {
    lt::Params p = layoutOf(n, false);
    p.start = {n / 4, 0};
    p.targets = {{3 * n / 4, n - 1}};
    lt::calibrate(p);
    out.push_back({std::to_string(n) + "² off-axis", "off-axis-" + std::to_string(n),
                   "a bolt on " + std::to_string(n) + "² to a point off-axis", p, pointRequest(p)});
  }
  {
    const lt::Params p = grounded(layoutOf(n, false));
    out.push_back({std::to_string(n) + "² ground", "ground-" + std::to_string(n),
                   "a bolt on " + std::to_string(n) + "² to the ground", p, pointRequest(p)});
  }
  if (!quick) {
    lt::Params wall = layoutOf(96, false);  // examples/04-storm-over-water.json's bolt
    wall.start = {20, 0};
    wall.targets = {{70, 95}};
    wall.obstacles.assign(96 * 96, 0);
    for (int y = 40; y < 46; ++y)
      for (int x = 30; x < 66; ++x) wall.obstacles[size_t(y) * 96 + size_t(x)] = 1;
    lt::calibrate(wall);
    json fixed = pointRequest(wall);
    fixed["obstacles"] = "a 36 × 6 wall";
    out.push_back({"96² wall (example 04)", "wall-96", "a bolt around a wall, 96² (example 04)", wall, fixed});
    lt::Params wide = layoutOf(128, false);
    wide.width = 256;
    wide.start = {128, 0};
    wide = grounded(wide);
    out.push_back({"256 × 128 ground", "ground-256x128", "a bolt on 256 × 128 to the ground", wide, pointRequest(wide)});
    const lt::Params volume = grounded(layoutOf(32, true));
    out.push_back({"32³ ground plane", "ground-32x32x32", "a bolt in 32³ to a ground plane", volume, pointRequest(volume)});
  }
  {
    const int length = quick ? 128 : 512;
    lt::Params c = layoutOf(32, false);
    c.width = 3, c.height = length;
    c.start = {1, 0};
    c.targets = {{1, length - 1}};
    lt::calibrate(c);
    out.push_back({"3 × " + std::to_string(length) + " channel", "channel", "", c, pointRequest(c), true});  // a stress case, no ask
  }
  return out;
}

void measure(Run& run) {
  const int seeds = run.quick ? 6 : 20, drawn = 4;
  for (const Layout& l : layouts(run.quick)) {
    std::fprintf(stderr, "           %s\n", l.name.c_str());
    Sheet sheet;
    sheet.id = "lightning-shape-" + l.id;
    sheet.width = l.params.width;
    sheet.height = l.params.height;
    sheet.columns = sheet.height * 4 < sheet.width * 3 ? 2 : 4;  // wide grids: larger panels
    sheet.caption = l.name + ": exact DBM (" + (sheet.columns == 4 ? "top row" : "top two rows") +
                    ") and fast calibrated (below), seeds 1 to " + std::to_string(drawn);
    if (!l.params.depth) addObstacles(sheet, l.params.obstacles);
    const bool drawn_ = l.params.width > 3 && run.timed;
    // Each seed's bolt (grown on every core): its shape, and the median bolt's time.
    struct Shapes {
      std::vector<lt::BoltShape> shapes;
      double ms = 0;
    };
    auto shapes = [&](const lt::Params& p, const char* label) {
      std::vector<std::optional<lt::Bolt>> bolts(static_cast<size_t>(seeds));
      onEveryCore(bolts.size(), [&](size_t j) {
        lt::Params q = p;
        q.seed = j + 1;
        if (auto b = lt::grow(q); b.ok()) bolts[j] = std::move(b.value());
      });
      Shapes out;
      std::vector<double> ms;
      for (size_t j = 0; j < bolts.size(); ++j) {
        if (!bolts[j]) continue;
        out.shapes.push_back(lt::shapeOf(*bolts[j], p.width, p.height, p.depth));
        ms.push_back(bolts[j]->stats.elapsedMs);
        if (label && drawn_ && int(j) < drawn) addPanel(sheet, *bolts[j], std::string(label) + " seed " + std::to_string(j + 1));
      }
      out.ms = quantile(ms, 0.5);
      return out;
    };
    lt::Params ref = l.params;
    ref.method = lt::Method::kDbm;
    ref.tolerance = 1e-8;
    const Shapes refShapes = shapes(ref, "dbm");
    struct Setting {
      std::string series, setting;
      json request;
      lt::Params params;
    };
    std::vector<Setting> settings;
    settings.push_back({"fast calibrated", "default", {{"method", "fast"}}, l.params});
    lt::Params paper = l.params;
    lt::usePaperConstants(paper);
    settings.push_back({"fast paper", "variant paper", {{"method", "fast"}, {"variant", "paper"}}, paper});
    if (!l.params.depth) {
      lt::Params charges = l.params;
      charges.method = lt::Method::kCharges;
      settings.push_back({"charges calibrated", "default", {{"method", "charges"}}, charges});
    }
    for (double tol : l.tolerances ? std::vector<double>{1e-1, 1e-2, 1e-4} : std::vector<double>{}) {
      lt::Params d = l.params;
      d.method = lt::Method::kDbm, d.solver = lt::Solver::kMgpcg, d.tolerance = tol;
      settings.push_back({"dbm-mgpcg", "tol " + fmt(tol, 1), {{"method", "dbm"}, {"solver", "mgpcg"}, {"tolerance", tol}}, d});
    }
    for (const Setting& s : settings) {
      const Shapes method = shapes(s.params, s.series == "fast calibrated" ? "fast" : nullptr);
      const auto& methodShapes = method.shapes;
      const auto d = lt::shapeDistance(methodShapes, refShapes.shapes);
      Row r;
      r.series = s.series + " " + l.name;
      r.setting = s.setting;
      r.group = l.name;
      r.request = s.request;
      // Fewer than two bolts on a side (failed growths) have no spread to measure against.
      r.errors["shape"] = methodShapes.size() < 2 || refShapes.shapes.size() < 2 ? NAN : d.worst;
      r.note = fmt(d.mean.cells, 4) + " / " + fmt(d.refMean.cells, 4) + ", " + fmt(d.mean.tips, 3) + " / " +
               fmt(d.refMean.tips, 3) + ", " + fmt(d.mean.dimension, 3) + " / " + fmt(d.refMean.dimension, 3) + " (z " +
               fmt(d.cells, 2) + ", " + fmt(d.tips, 2) + ", " + fmt(d.dimension, 2) + "; " +
               std::to_string(methodShapes.size()) + " seeds)";
      r.ticket = timeBolts(run, s.series + " " + s.setting + " " + l.name, s.params, seeds, method.ms);
      run.rows.push_back(r);
    }
    Row exact;
    exact.series = "dbm exact " + l.name;
    exact.setting = "reference";
    exact.group = l.name;
    exact.request = {{"method", "dbm"}, {"tolerance", 1e-8}};
    exact.errors["shape"] = 0;
    exact.note = std::to_string(refShapes.shapes.size()) + " seeds";
    exact.ticket = timeBolts(run, "dbm exact " + l.name, ref, seeds, refShapes.ms);
    run.rows.push_back(exact);
    if (drawn_) run.sheets.push_back(std::move(sheet));
  }
}

std::string conclude(const Run& run) {
  std::string c = "Indistinguishable from exact DBM at these seeds (every measure within 2 standard errors):";
  bool any = false;
  for (const Row& r : run.rows)
    if (r.setting != "reference" && errorOf(r, "shape") <= 2) c += " " + r.series + " " + r.setting + ";", any = true;
  if (!any) c += " none;";
  const Row* far = nullptr;
  for (const Row& r : run.rows)
    if (r.setting != "reference" && std::isfinite(errorOf(r, "shape")) && (!far || errorOf(r, "shape") > errorOf(*far, "shape")))
      far = &r;
  if (far)
    c += " furthest: " + far->series + " " + far->setting + " (" + fmt(errorOf(*far, "shape"), 3) +
         " standard errors: " + far->note + ").";
  return c + " The calibrated tables stay the fast method's default: no law measured meets DBM in every geometry. "
             "Seven shape measures per geometry and the laws tried: docs/lightning-shape.md.";
}

}  // namespace

Section lightningShapeSection() {
  Section s;
  s.id = "lightning-shape";
  s.effect = "lightning";
  s.title = "Lightning: cells, tips and D against exact DBM, in seed-noise units";
  s.reference = "exact DBM (capacitance, then MGPCG at 1e-8; DeepField below 1e-8) on the same layout over as many seeds";
  s.metrics = {{"shape", "z", "largest |mean difference| / standard error of cells, tips, D", 3.0,
                "3 standard errors: a bolt that seeds' noise does not explain"}};
  s.timeName = "ms per bolt (median)";
  s.settingName = "setting";
  s.noteName = "cells, tips, D (method / DBM)";
  s.code = {"effects/lightning"};
  for (const Layout& l : layouts(false))
    if (!l.ask.empty()) s.asks.push_back({l.name, l.ask, l.fixed});
  s.measure = measure;
  s.conclude = [](const Section&, const Run& run) { return conclude(run); };
  return s;
}

}  // namespace report
