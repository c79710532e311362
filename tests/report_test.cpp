// The error-against-run-time report tool, on its reduced configuration: it writes the
// report, the JSON and a plot per section, and wherever a setting converges to the reference
// (solver tolerance, table size, wavelength samples, ray-march steps) the error shrinks.
#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api/error_estimates.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The errors of `series` in report order (the order the setting is refined in).
std::vector<double> errorsOf(const json& section, const std::string& series, const std::string& settingPrefix = "") {
  std::vector<double> out;
  for (const auto& p : section["points"])
    if (p["series"] == series && p["setting"].get<std::string>().rfind(settingPrefix, 0) == 0)
      out.push_back(p["error"].get<double>());
  return out;
}

void expectShrinks(const std::vector<double>& e, const std::string& what, double slack = 1e-9) {
  ASSERT_GE(e.size(), 3u) << what;
  for (size_t i = 1; i < e.size(); ++i) EXPECT_LE(e[i], e[i - 1] * (1 + 1e-6) + slack) << what << " at step " << i;
  EXPECT_LT(e.back(), e.front()) << what;
}

TEST(ErrorReport, QuickRunWritesTheReportAndErrorsShrinkWhereSettingsConverge) {
  const fs::path out = fs::temp_directory_path() / ("effectd_report_" + std::to_string(::getpid()));
  fs::remove_all(out);
  const bool plots = std::system("gnuplot --version >/dev/null 2>&1") == 0;
  const std::string cmd = std::string(EFFECTD_ERROR_REPORT) + " --quick --out " + out.string() +
                          (plots ? "" : " --no-plots") + " 2>/dev/null";
  ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd;
  ASSERT_TRUE(fs::exists(out / "error-vs-time.md"));
  std::ifstream in(out / "error-vs-time.json");
  const json r = json::parse(in);
  for (const char* id : {"lightning-tv", "lightning-fd", "lightning-shape", "lightning3d-tv", "lightning3d-fd",
                         "fog-tables", "fog-height-march", "tangents", "thin-film", "render-bubble", "render-fog"}) {
    SCOPED_TRACE(id);
    ASSERT_TRUE(r.contains(id));
    EXPECT_FALSE(r[id]["conclusion"].get<std::string>().empty());
    // Every timed point carries its spread; every group a Pareto front and a choice per budget.
    for (const auto& p : r[id]["points"]) {
      if (p["ms"].get<double>() <= 0) continue;
      EXPECT_GE(p["repeats"].get<int>(), 3) << p;
      EXPECT_LE(p["msQ1"].get<double>(), p["ms"].get<double>()) << p;
      EXPECT_GE(p["msQ3"].get<double>(), p["ms"].get<double>()) << p;
      EXPECT_EQ(p["runMedians"].size(), 2u) << "each timing process's median (the quick run has 2)" << p;
    }
    ASSERT_FALSE(r[id]["pareto"].empty());
    for (const auto& [group, front] : r[id]["pareto"].items()) {
      EXPECT_FALSE(front.empty()) << group;
      EXPECT_TRUE(r[id]["budgets"][group].contains("offline (any time)")) << group;
    }
    if (plots) {
      EXPECT_TRUE(fs::exists(out / "error-vs-time" / (std::string(id) + ".png")));
    }
  }
  // DBM: tighter solver tolerance -> closer to the converged distribution, in either
  // neighbourhood; every lightning row says its seeds.
  for (const char* hood : {"8", "4"}) {
    const std::string grid = std::string("32², ") + hood + "-nbhd";
    expectShrinks(errorsOf(r["lightning-tv"], "dbm-mgpcg " + grid), "dbm TV over tolerance 1e-2, 1e-4, 1e-6 " + grid);
    EXPECT_EQ(errorsOf(r["lightning-fd"], "fast calibrated " + grid).size(), 1u) << grid;
    EXPECT_EQ(errorsOf(r["lightning-fd"], "fast paper " + grid, "variant paper").size(), 1u) << grid;
  }
  // Shapes against exact DBM in seed-noise units, in the open layout and in the 3-wide channel
  // (where the field ahead of the bolt falls below 1e-40): the reference and three MGPCG
  // tolerances in each.
  EXPECT_EQ(errorsOf(r["lightning-shape"], "dbm exact 3 × 128 channel").size(), 1u);
  EXPECT_EQ(errorsOf(r["lightning-shape"], "dbm-mgpcg 3 × 128 channel").size(), 3u);
  EXPECT_EQ(errorsOf(r["lightning-shape"], "fast calibrated 32² open").size(), 1u);
  const std::string md = [&] {
    std::ifstream m(out / "error-vs-time.md");
    return std::string(std::istreambuf_iterator<char>(m), {});
  }();
  EXPECT_NE(md.find("## Summary: what to choose"), std::string::npos);
  EXPECT_LT(md.find("## Summary"), md.find("## Lightning"));
  // 3-D: the same, on 16^3 in the 26-neighbourhood.
  expectShrinks(errorsOf(r["lightning3d-tv"], "dbm-mgpcg 16³, 26-nbhd"), "3-D dbm TV over tolerance");
  EXPECT_EQ(errorsOf(r["lightning3d-fd"], "fast calibrated 16³, 26-nbhd").size(), 1u);
  for (const char* id : {"lightning-tv", "lightning-fd", "lightning3d-tv", "lightning3d-fd"})
    for (const auto& p : r[id]["points"])
      EXPECT_NE(p["note"].get<std::string>().find("(3 seeds)"), std::string::npos) << p;
  // Fog tables: more entries -> smaller interpolation error, for every type.
  for (const char* type :
       {"EXPONENTIAL", "GL_EXP", "GL_EXP2", "DISTANCE_EXP2", "DISTANCE_GAUSSIAN", "GL_LINEAR", "HEIGHT"})
    expectShrinks(errorsOf(r["fog-tables"], type), type);
  // Height fog: more ray-march steps -> closer to the closed form.
  expectShrinks(errorsOf(r["fog-height-march"], "ray marching"), "ray marching");
  // Thin film: more wavelength samples -> smaller Delta E against 1 nm.
  expectShrinks(errorsOf(r["thin-film"], "Airy bands, 0-1000 nm"), "thin film");
  // 99-100 um: fringes finer than any band; the band means are the incoherent grey at every count.
  const std::vector<double> thick = errorsOf(r["thin-film"], "Airy bands, 99-100 um");
  ASSERT_EQ(thick.size(), 3u);
  for (double e : thick) EXPECT_LT(e, 1.0) << "thin film at 100 um";
  // Tangents: the approximations have a measured, nonzero error against MikkTSpace.
  for (const char* m : {"perTriangle", "perVertex"}) {
    auto e = errorsOf(r["tangents"], m);
    ASSERT_EQ(e.size(), 2u);
    EXPECT_GT(e[1], 0.1) << m << " on the mirrored torus";
  }
  // Render previews: the film model closer to the reference than the paper's; the fog pass
  // within 2 steps of 8-bit colour of the closed form (what X-Effect-Error says of it).
  const std::vector<double> paper = errorsOf(r["render-bubble"], "paper (eqns 3-11)"),
                            film = errorsOf(r["render-bubble"], "film + far side + highlight (default)");
  ASSERT_EQ(paper.size(), 1u);
  ASSERT_EQ(film.size(), 1u);
  EXPECT_LT(film[0], paper[0] / 2);
  ASSERT_EQ(r["render-fog"]["points"].size(), 5u);
  for (const auto& p : r["render-fog"]["points"]) EXPECT_LE(p["error"].get<double>(), 2.0) << p;
  fs::remove_all(out);
}

// The figures answers state when they were not measured (server/api/error_estimates.h) are the
// committed report's measurements, to 2 %: regenerating the report with other numbers fails here.
TEST(ErrorReport, EstimatesAreTheCommittedReportsFigures) {
  std::ifstream in(std::string(EFFECTD_SOURCE_DIR) + "/docs/error-vs-time.json");
  const json r = json::parse(in);
  auto expectReported = [&](const effectd::ErrorEstimate& e) {
    SCOPED_TRACE(e.section + ": " + e.row + ", " + e.setting);
    ASSERT_TRUE(r.contains(e.section));
    const std::vector<double> measured = errorsOf(r[e.section], e.row, e.setting);
    ASSERT_EQ(measured.size(), 1u);
    EXPECT_NEAR(e.value, measured[0], 0.02 * measured[0]);
  };
  namespace bb = effects::bubble;
  namespace lt = effects::lightning;
  namespace tg = effects::tangents;
  const auto with = [](bb::Shading shading, bool iridescence, bool backFace, bool highlight) {
    bb::Features f;
    f.shading = shading, f.iridescence = iridescence, f.backFace = backFace, f.highlight = highlight;
    return f;
  };
  for (const bb::Features& f : {with(bb::Shading::kPaper, false, true, true), with(bb::Shading::kPaper, true, true, true),
                                with(bb::Shading::kFilm, false, false, false), with(bb::Shading::kFilm, false, true, false),
                                with(bb::Shading::kFilm, false, true, true)})
    expectReported(effectd::shadingErrorEstimate(f));
  for (lt::Method m : {lt::Method::kFast, lt::Method::kCharges, lt::Method::kDbm})
    for (int n : {64, 128})
      for (int hood : {8, 4}) {
        lt::Params p;
        p.method = m, p.width = p.height = n, p.neighbourhood = hood;
        expectReported(effectd::lightningErrorEstimate(p));
      }
  for (lt::Solver solver : {lt::Solver::kMgpcg, lt::Solver::kCg})
    for (double tol : {1e-2, 1e-4, 1e-6, 1e-8}) {
      lt::Params p;
      p.method = lt::Method::kDbm, p.solver = solver, p.tolerance = tol;
      expectReported(effectd::lightningErrorEstimate(p));
    }
  for (lt::Method m : {lt::Method::kFast, lt::Method::kDbm}) {
    lt::Params p;
    p.method = m, p.width = p.height = p.depth = 32, p.neighbourhood = 26;
    expectReported(effectd::lightningErrorEstimate(p));
  }
  for (tg::Mode m : {tg::Mode::kPerVertex, tg::Mode::kPerTriangle}) {  // the worse of the two meshes
    const effectd::ErrorEstimate e = effectd::tangentsErrorEstimate(m);
    double worst = 0;
    for (const auto& p : r["tangents"]["points"])
      if (p["series"] == e.row) worst = std::max(worst, p["error"].get<double>());
    EXPECT_NEAR(e.value, worst, 0.02 * worst) << e.row;
  }
  EXPECT_EQ(effectd::tangentsErrorEstimate(tg::Mode::kMikkTSpace).value, 0.0);
}

}  // namespace
