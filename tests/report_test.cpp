// The error report (bench/error_report, docs/reports.md): its reduced configuration writes every
// section's data, wherever a setting converges to the reference (solver tolerance, table size,
// wavelength samples, ray-march steps) the error shrinks, the check fails on a moved number and
// names the section, and every figure the server states is in the committed data.
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>

#include <unistd.h>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "api/error_estimates.h"

namespace {

namespace fs = std::filesystem;
using nlohmann::json;

// The errors of `series` for `metric`, in report order (the order the setting is refined in).
std::vector<double> errorsOf(const json& section, const std::string& series, const std::string& metric,
                             const std::string& settingPrefix = "") {
  std::vector<double> out;
  for (const auto& r : section["rows"])
    if (r["series"] == series && r["setting"].get<std::string>().rfind(settingPrefix, 0) == 0 &&
        r["errors"].contains(metric))
      out.push_back(r["errors"][metric].get<double>());
  return out;
}

void expectShrinks(const std::vector<double>& e, const std::string& what, double slack = 1e-9) {
  ASSERT_GE(e.size(), 3u) << what;
  for (size_t i = 1; i < e.size(); ++i) EXPECT_LE(e[i], e[i - 1] * (1 + 1e-6) + slack) << what << " at step " << i;
  EXPECT_LT(e.back(), e.front()) << what;
}

json readJson(const fs::path& p) {
  std::ifstream in(p);
  return json::parse(in);
}

int run(const std::string& cmd) {
  const int status = std::system(cmd.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ErrorReport, QuickRunWritesEverySectionAndErrorsShrinkWhereSettingsConverge) {
  const fs::path out = fs::temp_directory_path() / ("effectd_report_" + std::to_string(::getpid()));
  fs::remove_all(out);
  ASSERT_EQ(run(std::string(EFFECTD_ERROR_REPORT) + " --quick --out " + out.string() + " 2>/dev/null"), 0);
  std::map<std::string, json> r;
  for (const char* id : {"lightning", "lightning3d", "lightning-shape", "fog-tables", "fog-height-march",
                         "fog-conventions", "tangents", "thin-film", "glow-apsf", "render-bubble", "render-fog",
                         "render-lightning"}) {
    SCOPED_TRACE(id);
    ASSERT_TRUE(fs::exists(out / (std::string(id) + ".json")));
    const json s = readJson(out / (std::string(id) + ".json"));
    EXPECT_FALSE(s["conclusion"].get<std::string>().empty());
    EXPECT_FALSE(s["metrics"].empty());
    for (const auto& m : s["metrics"]) EXPECT_TRUE(m["limit"].is_number()) << m;
    EXPECT_EQ(s["check"]["rows"].size(), s["rows"].size()) << "the quick run is its own check configuration";
    // Every timed row carries its spread, from each of the 2 timing processes; every row its errors.
    for (const auto& row : s["rows"]) {
      EXPECT_FALSE(row["errors"].empty()) << row;
      if (!row.contains("time")) continue;
      const json& t = row["time"];
      EXPECT_GE(t["repeats"].get<int>(), 3) << row;
      EXPECT_LE(t["q1"].get<double>(), t["ms"].get<double>()) << row;
      EXPECT_GE(t["q3"].get<double>(), t["ms"].get<double>()) << row;
      EXPECT_EQ(t["runMedians"].size(), 2u) << row;
    }
    r[id] = s;
  }
  // DBM: tighter solver tolerance -> closer to the converged distribution, in either
  // neighbourhood; every lightning row says its seeds and the request that grows it.
  for (const char* hood : {"8", "4"}) {
    const std::string grid = std::string("32², ") + hood + "-nbhd";
    expectShrinks(errorsOf(r["lightning"], "dbm-mgpcg " + grid, "tv"), "dbm TV over tolerance 1e-2, 1e-4, 1e-6 " + grid);
    EXPECT_EQ(errorsOf(r["lightning"], "fast calibrated " + grid, "fd").size(), 1u) << grid;
    EXPECT_EQ(errorsOf(r["lightning"], "fast paper " + grid, "fd", "variant paper").size(), 1u) << grid;
  }
  for (const auto& row : r["lightning"]["rows"]) {
    EXPECT_NE(row["note"].get<std::string>().find("(3 seeds)"), std::string::npos) << row;
    EXPECT_TRUE(row["request"].contains("method")) << row;
  }
  // Shapes against exact DBM in seed-noise units, in the open layout and in the 3-wide channel
  // (where the field ahead of the bolt falls below 1e-40): the reference and three MGPCG
  // tolerances in each.
  EXPECT_EQ(errorsOf(r["lightning-shape"], "dbm exact 3 × 128 channel", "shape").size(), 1u);
  EXPECT_EQ(errorsOf(r["lightning-shape"], "dbm-mgpcg 3 × 128 channel", "shape").size(), 3u);
  EXPECT_EQ(errorsOf(r["lightning-shape"], "fast calibrated 32² open", "shape").size(), 1u);
  // 3-D: the same, on 16^3 in the 26-neighbourhood.
  expectShrinks(errorsOf(r["lightning3d"], "dbm-mgpcg 16³, 26-nbhd", "tv"), "3-D dbm TV over tolerance");
  // Fog tables: more entries -> smaller interpolation error, for every type.
  for (const char* type : {"EXPONENTIAL", "GL_EXP", "GL_EXP2", "DISTANCE_EXP2", "DISTANCE_GAUSSIAN", "GL_LINEAR", "HEIGHT"})
    expectShrinks(errorsOf(r["fog-tables"], type, "maxError"), type);
  expectShrinks(errorsOf(r["fog-height-march"], "ray marching", "maxError"), "ray marching");
  expectShrinks(errorsOf(r["thin-film"], "Airy bands, 0-1000 nm", "meanDeltaE"), "thin film");
  // 99-100 um: fringes finer than any band; the band means are the incoherent grey at every count.
  const std::vector<double> thick = errorsOf(r["thin-film"], "Airy bands, 99-100 um", "meanDeltaE");
  ASSERT_EQ(thick.size(), 3u);
  for (double e : thick) EXPECT_LT(e, 1.0) << "thin film at 100 um";
  for (const char* m : {"perTriangle", "perVertex"}) {  // a measured, nonzero error against MikkTSpace
    const auto e = errorsOf(r["tangents"], m, "meanAngleDeg");
    ASSERT_EQ(e.size(), 2u);
    EXPECT_GT(e[1], 0.1) << m << " on the mirrored torus";
  }
  // Render previews: the film model closer to the reference than the paper's; the fog pass
  // within 2 steps of 8-bit colour of the closed form.
  const auto paper = errorsOf(r["render-bubble"], "paper (eqns 3-11)", "meanDeltaE"),
             film = errorsOf(r["render-bubble"], "film + far side + highlight (default)", "meanDeltaE");
  ASSERT_EQ(paper.size(), 1u);
  ASSERT_EQ(film.size(), 1u);
  EXPECT_LT(film[0], paper[0] / 2);
  ASSERT_EQ(r["render-fog"]["rows"].size(), 5u);
  for (const auto& row : r["render-fog"]["rows"]) EXPECT_LE(row["errors"]["maxSteps"].get<double>(), 2.0) << row;
  // The renderer makes a page of it, with the summary first.
  const fs::path md = out / "report.md";
  ASSERT_EQ(run("python3 " EFFECTD_SOURCE_DIR "/scripts/report_render.py --no-plots --data " + out.string() + " --out " +
                md.string() + " >/dev/null"),
            0);
  std::ifstream m(md);
  const std::string page((std::istreambuf_iterator<char>(m)), {});
  EXPECT_LT(page.find("## Summary"), page.find("## Lightning"));
  fs::remove_all(out);
}

// A check that cannot fail is not a check: one moved number in a copy of the committed data
// stales that section, named with its command, and only it.
TEST(ErrorReport, CheckNamesTheSectionWhoseNumbersMoved) {
  const fs::path data = fs::temp_directory_path() / ("effectd_check_" + std::to_string(::getpid()));
  fs::remove_all(data);
  fs::create_directories(data);
  for (const char* id : {"fog-height-march", "fog-conventions"})
    fs::copy_file(fs::path(EFFECTD_SOURCE_DIR) / "docs/error-vs-time" / (std::string(id) + ".json"), data / (std::string(id) + ".json"));
  const std::string check = std::string(EFFECTD_ERROR_REPORT) + " --check --section fog-height-march --section fog-conventions --data " +
                            data.string() + " > " + (data / "out.txt").string();
  ASSERT_EQ(run(check), 0) << "the committed data is current";
  json s = readJson(data / "fog-height-march.json");
  json& e = s["check"]["rows"][2]["errors"]["maxError"];
  e = e.get<double>() * (1 + 1e-6);
  std::ofstream(data / "fog-height-march.json") << s.dump();
  EXPECT_EQ(run(check), 1);
  std::ifstream in(data / "out.txt");
  const std::string said((std::istreambuf_iterator<char>(in)), {});
  EXPECT_NE(said.find("STALE   fog-height-march"), std::string::npos) << said;
  EXPECT_NE(said.find("scripts/report.sh --section fog-height-march"), std::string::npos) << said;
  EXPECT_NE(said.find("current fog-conventions"), std::string::npos) << said;
  fs::remove_all(data);
}

// Every figure an answer can state comes from the committed data (embedded at build time), with
// its limit of use.
TEST(ErrorReport, EveryFigureTheServerStatesIsInTheData) {
  auto expectStated = [](const effectd::ErrorEstimate& e) {
    SCOPED_TRACE(e.section + ": " + e.row + ", " + e.setting);
    EXPECT_TRUE(std::isfinite(e.value));
    EXPECT_GE(e.value, 0);
    EXPECT_TRUE(std::isfinite(e.limit));
  };
  namespace bb = effects::bubble;
  namespace lt = effects::lightning;
  namespace tg = effects::tangents;
  for (bool paper : {false, true})
    for (bool iridescence : {false, true})
      for (bool backFace : {false, true})
        for (bool highlight : {false, true}) {
          bb::Features f;
          f.shading = paper ? bb::Shading::kPaper : bb::Shading::kFilm;
          f.iridescence = iridescence, f.backFace = backFace, f.highlight = highlight;
          expectStated(effectd::shadingErrorEstimate(f));
        }
  for (lt::Method m : {lt::Method::kFast, lt::Method::kCharges, lt::Method::kDbm})
    for (int n : {16, 64, 128, 1024})
      for (int hood : {8, 4}) {
        lt::Params p;
        p.method = m, p.width = p.height = n, p.neighbourhood = hood;
        expectStated(effectd::lightningErrorEstimate(p));
        p.depth = n, p.neighbourhood = 26;
        if (m != lt::Method::kCharges) expectStated(effectd::lightningErrorEstimate(p));
      }
  for (lt::Solver solver : {lt::Solver::kMgpcg, lt::Solver::kCg})
    for (double tol : {1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-12}) {
      lt::Params p;
      p.method = lt::Method::kDbm, p.solver = solver, p.tolerance = tol;
      expectStated(effectd::lightningErrorEstimate(p));
    }
  for (tg::Mode m : {tg::Mode::kMikkTSpace, tg::Mode::kPerVertex, tg::Mode::kPerTriangle})
    expectStated(effectd::tangentsErrorEstimate(m));
  EXPECT_EQ(effectd::tangentsErrorEstimate(tg::Mode::kMikkTSpace).value, 0.0);
  expectStated(effectd::fogPassErrorEstimate());
  expectStated(effectd::lightningPassErrorEstimate());
  EXPECT_EQ(effectd::lightningPassErrorEstimate().limit, 1.75);
}

}  // namespace
