// The report's figures for answers that were not measured (error_estimates.h), read from the
// report's embedded data.
#include "api/error_estimates.h"

#include <algorithm>
#include <cstdio>
#include <map>

#include <nlohmann/json.hpp>

#include "contract/resources.h"

namespace effectd {

namespace lt = effects::lightning;
using nlohmann::json;

namespace {

// Each embedded section's data, parsed once.
const json& section(const std::string& id) {
  static const std::map<std::string, json> sections = [] {
    std::map<std::string, json> out;
    for (const auto& [path, text] : reportResources()) {
      json j = json::parse(text.begin(), text.end(), nullptr, false);
      if (!j.is_object()) continue;
      const std::string id = j.value("id", "");  // before the move: json's operator= takes its copy first
      out[id] = std::move(j);
    }
    return out;
  }();
  static const json none = json::object();
  const auto it = sections.find(id);
  return it == sections.end() ? none : it->second;
}

}  // namespace

ErrorEstimate reported(const std::string& id, const std::string& series, const std::string& settingPrefix,
                       const std::string& metric) {
  ErrorEstimate e;
  e.section = id, e.row = series, e.setting = settingPrefix;
  const json& s = section(id);
  for (const json& m : s.value("metrics", json::array()))
    if (m.value("id", "") == metric && m["limit"].is_number()) e.limit = m["limit"].get<double>();
  for (const json& r : s.value("rows", json::array())) {
    if ((!series.empty() && r.value("series", "") != series) || r.value("setting", "").rfind(settingPrefix, 0) != 0)
      continue;
    const json v = r["errors"].value(metric, json());
    if (!v.is_number()) continue;
    if (!(e.value >= v.get<double>())) e.value = v.get<double>(), e.setting = r["setting"].get<std::string>();
  }
  return e;
}

ErrorEstimate lightningErrorEstimate(const lt::Params& p) {
  if (p.method == lt::Method::kDbm && p.solver != lt::Solver::kCapacitance) {
    // the report's tolerances 1e-2, 1e-4, 1e-6, 1e-8: the nearest
    const int i = int(std::clamp(std::round(-std::log10(std::max(p.tolerance, 1e-300)) / 2) - 1, 0.0, 3.0));
    char tol[32];
    std::snprintf(tol, sizeof tol, "tol %g", std::pow(10.0, -2.0 * (i + 1)));
    return reported("lightning", std::string("dbm-") + lt::toString(p.solver) + " 64², 8-nbhd", tol, "tv");
  }
  if (p.depth) return reported("lightning3d", (p.method == lt::Method::kDbm ? "dbm-capacitance" : "fast calibrated") + std::string(" 32³, 26-nbhd"), "default", "tv");
  const bool large = std::max(p.width, p.height) > 96, four = p.neighbourhood == 4;
  const std::string grid = std::string(large ? "128², " : "64², ") + (four ? "4" : "8") + "-nbhd";
  switch (p.method) {
    case lt::Method::kCharges: return reported("lightning", "charges calibrated " + grid, "default", "tv");
    case lt::Method::kDbm: return reported("lightning", "dbm-capacitance " + grid, "default", "tv");
    default: return reported("lightning", "fast calibrated " + grid, "default", "tv");
  }
}

ErrorEstimate tangentsErrorEstimate(effects::tangents::Mode mode) {
  return reported("tangents", effects::tangents::toString(mode), "", "meanAngleDeg");
}

ErrorEstimate shadingErrorEstimate(const effects::bubble::Features& f) {
  using effects::bubble::Shading;
  const char* row = f.shading == Shading::kPaper ? (f.iridescence ? "paper + film table" : "paper (eqns 3-11)")
                    : !f.backFace                ? "film, near side"
                    : f.highlight                ? "film + far side + highlight (default)"
                                                 : "film + far side";
  return reported("render-bubble", row, "", "meanDeltaE");
}

ErrorEstimate fogPassErrorEstimate() { return reported("render-fog", "", "", "maxSteps"); }

ErrorEstimate lightningPassErrorEstimate() { return reported("render-lightning", "128 grid, core 1.5", "", "maxOffsetPx"); }

}  // namespace effectd
