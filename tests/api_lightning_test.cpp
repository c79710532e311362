// POST /v1/lightning over HTTP.
#include <sys/resource.h>

#include <algorithm>
#include <cmath>

#include <effects/common.h>

#include "api/error_estimates.h"
#include "contract/codec.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

json request(int n) {
  return {{"grid", {{"width", n}, {"height", n}}}, {"start", {n / 2, 0}}, {"targets", {{n / 2, n - 1}}}, {"seed", 4}};
}

TEST(LightningApi, OnlyWhatIsIncluded) {
  TestServer s;
  auto r = s.postJson("/v1/lightning", request(48));
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_EQ(j["method"], "fast");
  ASSERT_TRUE(j.contains("polylines"));
  for (const char* absent : {"cells", "tree", "stats", "error", "fractalDimension", "guide"})
    EXPECT_FALSE(j.contains(absent)) << absent;
  // Not measured, yet the answer says how far such a bolt is from DBM, and that it is the report's.
  effects::lightning::Params p;
  p.width = p.height = 64;
  const effectd::ErrorEstimate e = effectd::lightningErrorEstimate(p);  // the report's data, embedded
  ASSERT_TRUE(std::isfinite(e.value)) << e.row;
  char stated[96];
  std::snprintf(stated, sizeof stated, "meanTotalVariation=%.3g; limit=0.5; kind=estimate; row=\"fast calibrated 64^2, 8-nbhd, default", e.value);
  EXPECT_EQ(r->get_header_value("X-Effect-Error").rfind(stated, 0), 0u)
      << r->get_header_value("X-Effect-Error");
  for (unsigned char c : r->get_header_value("X-Effect-Error")) EXPECT_LT(c, 0x80) << "header values are ASCII";
  const json& main = j["polylines"][0];
  EXPECT_EQ(main["channel"], "main");
  EXPECT_EQ(main["points"].size(), 2 * main["step"].size());
  if (j["polylines"].size() > 1) {
    EXPECT_EQ(main["width"].get<double>(), 2 * j["polylines"][1]["width"].get<double>());
  }

  json req = request(48);
  req["include"] = {"cells", "tree", "fractalDimension", "stats"};
  j = json::parse(s.postJson("/v1/lightning", req)->body);
  EXPECT_FALSE(j.contains("polylines"));
  EXPECT_EQ(j["cells"].size(), 2 * j["tree"]["parent"].size());
  double d = j["fractalDimension"].get<double>();
  EXPECT_TRUE(d > 0.8 && d <= 2.0) << d;  // a thin 48x48 bolt is close to a line
  EXPECT_TRUE(j["stats"].contains("elapsedMs"));
}

TEST(LightningApi, SameSeedSameBytesOtherJitterSeedSameCells) {
  TestServer s;
  json req = request(64);
  req["include"] = {"polylines", "cells"};
  auto a = s.postJson("/v1/lightning", req), b = s.postJson("/v1/lightning", req);
  EXPECT_EQ(a->body, b->body);
  req["shape"] = {{"jitterSeed", 77}};
  json c = json::parse(s.postJson("/v1/lightning", req)->body), ja = json::parse(a->body);
  EXPECT_EQ(c["cells"], ja["cells"]);
  EXPECT_NE(c["polylines"], ja["polylines"]);
}

TEST(LightningApi, TimelineParallelToPolylinesAndItsOwnSeed) {
  TestServer s;
  json req = request(64);
  req["include"] = {"polylines", "timeline"};
  auto r = s.postJson("/v1/lightning", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json a = json::parse(r->body);
  EXPECT_EQ(a["variant"], "calibrated");
  const json& tl = a["timeline"];
  ASSERT_EQ(tl["polylines"].size(), a["polylines"].size());
  for (size_t i = 0; i < a["polylines"].size(); ++i) {
    EXPECT_EQ(tl["polylines"][i]["leader"].size(), a["polylines"][i]["step"].size());
    EXPECT_EQ(tl["polylines"][i]["strokeDelay"].size(), a["polylines"][i]["step"].size());
  }
  const size_t keyframes = tl["keyframes"]["t"].size();
  for (const char* c : {"leader", "main", "branches"}) EXPECT_EQ(tl["keyframes"][c].size(), keyframes) << c;
  EXPECT_GT(tl["duration"].get<double>(), tl["connect"].get<double>());

  // Another animation seed: the same bolt, another strike; timeScale stretches it.
  req["animationSeed"] = 99;
  req["timeScale"] = 4;
  json b = json::parse(s.postJson("/v1/lightning", req)->body);
  EXPECT_EQ(b["polylines"], a["polylines"]);
  EXPECT_NE(b["timeline"]["strokes"], a["timeline"]["strokes"]);
  EXPECT_GT(b["timeline"]["connect"].get<double>(), 2 * a["timeline"]["connect"].get<double>());

  req["variant"] = "paper";
  EXPECT_EQ(json::parse(s.postJson("/v1/lightning", req)->body)["variant"], "paper");
  req["timeline"] = {{"leaderPause", {50, 20}}};
  json p = expectProblem(s.postJson("/v1/lightning", req), 400);
  EXPECT_TRUE(hasPointer(p, "/timeline/leaderPause")) << p.dump();
}

// dbm: the exact capacitance solver by default, MGPCG or CG on request; the answer names the
// solver that ran and the steps solved directly.
TEST(LightningApi, DbmNamesTheSolverThatRan) {
  TestServer s;
  json req = request(40);
  req["method"] = "dbm";
  req["include"] = {"stats", "cells"};
  json direct = json::parse(s.postJson("/v1/lightning", req)->body);
  EXPECT_EQ(direct["method"], "dbm-capacitance") << direct;
  EXPECT_GT(direct["stats"]["counters"]["directSteps"].get<double>(), 10) << direct;
  EXPECT_LE(direct["stats"]["counters"]["residual"].get<double>(), 1e-12) << direct;
  req["solver"] = "mgpcg";
  req["tolerance"] = 1e-10;
  json iterative = json::parse(s.postJson("/v1/lightning", req)->body);
  EXPECT_EQ(iterative["method"], "dbm-mgpcg");
  EXPECT_EQ(iterative["stats"]["counters"]["directSteps"], 0);
  EXPECT_EQ(iterative["cells"], direct["cells"]) << "the same bolt: both solve the same problem";
  req["solver"] = "direct";
  json p = expectProblem(s.postJson("/v1/lightning", req), 400);
  EXPECT_TRUE(hasPointer(p, "/solver")) << p.dump();
}

// charges: the calibrated power by default (named in stats), eta itself in the paper variant.
TEST(LightningApi, ChargesVariantChoosesThePower) {
  TestServer s;
  json req = request(32);
  req["method"] = "charges";
  req["include"] = {"stats"};
  json a = json::parse(s.postJson("/v1/lightning", req)->body);
  EXPECT_EQ(a["variant"], "calibrated");
  EXPECT_GT(a["stats"]["counters"]["chargesEta"].get<double>(), 2 * req.value("eta", 2.0)) << a;
  req["variant"] = "paper";
  req["eta"] = 3;
  a = json::parse(s.postJson("/v1/lightning", req)->body);
  EXPECT_EQ(a["variant"], "paper");
  EXPECT_EQ(a["stats"]["counters"]["chargesEta"], 3.0) << a;
  req["method"] = "dbm";
  EXPECT_FALSE(json::parse(s.postJson("/v1/lightning", req)->body).contains("variant"));
}

TEST(LightningApi, FourNeighbourhoodGrowsFourConnectedTrees) {
  TestServer s;
  for (const char* method : {"fast", "dbm", "charges"}) {
    json req = request(32);
    req["neighbourhood"] = 4;
    req["method"] = method;
    req["include"] = {"cells", "tree"};
    auto r = s.postJson("/v1/lightning", req);
    ASSERT_EQ(r->status, 200) << r->body;
    json a = json::parse(r->body);
    const json &cells = a["cells"], &parent = a["tree"]["parent"];
    for (size_t i = 1; i < parent.size(); ++i) {
      const size_t q = parent[i].get<size_t>();
      EXPECT_EQ(std::abs(cells[2 * i].get<int>() - cells[2 * q].get<int>()) +
                    std::abs(cells[2 * i + 1].get<int>() - cells[2 * q + 1].get<int>()),
                1)
          << method << " cell " << i;
    }
  }
  json req = request(32);
  req["neighbourhood"] = 6;
  json p = expectProblem(s.postJson("/v1/lightning", req), 400);
  EXPECT_TRUE(hasPointer(p, "/neighbourhood")) << p.dump();
}

// An empty list of rects or rows blocks no cell on a 2-D grid: the grid stays open (no A*
// guide under guide "auto"), the same bolt as without "obstacles"; one rect is a grid with
// obstacles, guided.
TEST(LightningApi, EmptyObstacleListsLeaveTheGridOpen) {
  TestServer s;
  json open = request(48);
  open["include"] = {"cells", "guide"};
  const std::string plain = s.postJson("/v1/lightning", open)->body;
  for (const char* form : {"rects", "rows"}) {
    json empty = open;
    empty["obstacles"] = {{form, json::array()}};
    auto r = s.postJson("/v1/lightning", empty);
    ASSERT_EQ(r->status, 200) << r->body;
    EXPECT_EQ(json::parse(r->body)["cells"], json::parse(plain)["cells"]) << form;
    EXPECT_TRUE(json::parse(r->body)["guide"].empty()) << form;
  }
  json walled = open;
  walled["obstacles"] = {{"rects", {{0, 20, 10, 2}}}};
  auto r = s.postJson("/v1/lightning", walled);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_FALSE(json::parse(r->body)["guide"].empty());
}

TEST(LightningApi, LargeGridWithBitmapObstacles) {
  TestServer s;
  const int n = 1024;
  std::string bits((size_t(n) * n + 7) / 8, '\0');
  effects::Rng rng(5);
  for (size_t i = 0; i < size_t(n) * n; ++i) {
    int x = int(i % n);
    bool passage = x >= 500 && x < 524;
    if (!passage && rng.uniform() < 0.2) bits[i / 8] = char(uint8_t(bits[i / 8]) | (0x80u >> (i % 8)));
  }
  json req = request(n);
  req["obstacles"] = {{"bitmap", base64Encode(bits)}};
  req["include"] = {"guide", "stats"};
  auto r = s.postJson("/v1/lightning", req);
  ASSERT_EQ(r->status, 200) << r->body.substr(0, 500);
  json j = json::parse(r->body);
  EXPECT_FALSE(j["guide"].empty());
}

TEST(LightningApi, GridAtTheConfiguredMaximum) {
  // 4096^2 (the default --max-grid-cells) with walls across 60 % of the rows, each with one
  // gap at alternating ends: finite output, memory bounded by the grid; one more row -> 413.
  TestServer s;
  const int n = 4096;
  json req = request(n);
  json rects = json::array();
  for (int k = 0; k < 6; ++k) {
    int y = 400 + k * 600;
    rects.push_back(k % 2 ? json{64, y, n - 64, 360} : json{0, y, n - 64, 360});  // x, y, w, h
  }
  req["obstacles"] = {{"rects", rects}};
  req["include"] = {"polylines", "stats", "guide"};
  struct rusage before {};
  getrusage(RUSAGE_SELF, &before);
  auto r = s.postJson("/v1/lightning", req);
  ASSERT_EQ(r->status, 200) << r->body.substr(0, 500);
  struct rusage after {};
  getrusage(RUSAGE_SELF, &after);
  json j = json::parse(r->body);
  EXPECT_GE(j["guide"].size(), 6u);
  size_t vertices = 0;
  for (const json& line : j["polylines"])
    for (const json& v : line["points"]) {
      ASSERT_TRUE(v.is_number() && std::isfinite(v.get<double>()));
      ASSERT_TRUE(v.get<double>() >= 0 && v.get<double>() <= n);
      ++vertices;
    }
  EXPECT_GT(vertices, 2u * n);  // the bolt winds through every gap
  // Growth state is about 26 bytes per cell (boundary map ~1 byte): well under 64 per cell.
  EXPECT_LT((after.ru_maxrss - before.ru_maxrss) * 1024.0, 64.0 * n * n);

  json big = request(n);
  big["grid"]["height"] = n + 1;
  auto p = expectProblem(s.postJson("/v1/lightning", big), 413);
  EXPECT_TRUE(hasPointer(p, "/grid")) << p;
  EXPECT_NE(p.value("detail", "").find("--max-grid-cells"), std::string::npos) << p;
  json dbm = request(n);
  dbm["method"] = "dbm";
  p = expectProblem(s.postJson("/v1/lightning", dbm), 413);
  EXPECT_NE(p.value("detail", "").find("--max-solver-grid-cells"), std::string::npos) << p;
}

TEST(LightningApi, WalledTargetIs422NotAHang) {
  TestServer s;
  json req = request(64);
  req["obstacles"] = {{"rects", {{0, 30, 64, 2}}}};
  for (const char* m : {"fast", "dbm", "charges"}) {
    req["method"] = m;
    auto p = expectProblem(s.postJson("/v1/lightning", req), 422);
    EXPECT_TRUE(hasPointer(p, "/targets/0")) << p;
  }
}

// 3-D: a bolt from a cloud layer down to a tower, around a building block, in world units.
json volumeRequest() {
  return {
      {"grid", {{"width", 32}, {"height", 32}, {"depth", 32}}},
      {"start", {16, 0, 16}},
      {"targets", {{20, 31, 8}}},
      {"world", {{"origin", {-16.0, 32.0, 16.0}}, {"cellSize", 0.5}}},
      {"obstacles",
       {{"boxes", {{6, 14, 6, 14, 6, 14}}},
        {"rows", {{{"y", 25}, {"z", 3}, {"runs", {{0, 10}, {20, 5}}}}}},
        {"spheres", {{{"center", {-8.0, 20.0, 4.0}}, {"radius", 2.0}}}},
        {"mesh", {{"positions", {-14.0, 28.0, 14.0, 2.0, 28.0, 14.0, -14.0, 28.0, -2.0}}, {"indices", {0, 1, 2}}}}}},
      {"seed", 3},
      {"include", {"polylines", "cells", "guide", "fractalDimension", "timeline"}}};
}

TEST(LightningApi, VolumeBoltInWorldUnits) {
  TestServer s;
  auto r = s.postJson("/v1/lightning", volumeRequest());
  ASSERT_EQ(r->status, 200) << r->body;
  const json j = json::parse(r->body);
  EXPECT_EQ(j["grid"], json::array({32, 32, 32}));
  EXPECT_EQ(j["world"]["cellSize"], 0.5);
  const json& cells = j["cells"];
  ASSERT_EQ(cells.size() % 3, 0u);
  for (size_t i = 0; i < cells.size(); i += 3) {
    const int x = cells[i], y = cells[i + 1], z = cells[i + 2];
    EXPECT_FALSE(x >= 6 && x < 20 && y >= 14 && y < 20 && z >= 6 && z < 20) << "inside the box";
  }
  // Points: three per vertex, in world units inside the grid's box.
  for (const auto& line : j["polylines"]) {
    ASSERT_EQ(line["points"].size(), 3 * line["step"].size());
    for (size_t i = 0; i < line["points"].size(); i += 3) {
      const double x = line["points"][i], y = line["points"][i + 1], z = line["points"][i + 2];
      EXPECT_TRUE(x >= -16 && x <= 0 && y >= 16 && y <= 32 && z >= 0 && z <= 16) << x << " " << y << " " << z;
    }
  }
  EXPECT_EQ(j["polylines"][0]["width"], 2 * 0.5);
  EXPECT_EQ(j["timeline"]["polylines"].size(), j["polylines"].size());
  for (const auto& g : j["guide"]) EXPECT_EQ(g.size(), 3u);
  // Same request, same bytes.
  EXPECT_EQ(s.postJson("/v1/lightning", volumeRequest())->body, r->body);
}

TEST(LightningApi, VolumeObstaclesFromAGlb) {
  // The bubble's own glTF (a unit sphere) scaled into the grid blocks the voxels of its surface.
  TestServer s;
  auto glb = s.postJson("/v1/bubble", json{{"mesh", {{"level", 2}, {"radius", 6}}}, {"format", "glb"}});
  ASSERT_EQ(glb->status, 200);
  json req = volumeRequest();
  req["obstacles"] = {{"glb", base64Encode(glb->body)}};
  req["world"] = {{"origin", {-16.0, 16.0, 16.0}}, {"cellSize", 1.0}};  // the sphere's centre is voxel (16, 16, 16)
  req["start"] = {16, 0, 16};
  req["targets"] = {{16, 16, 16}};  // inside the hollow sphere: unreachable through its surface
  auto r = s.postJson("/v1/lightning", req);
  EXPECT_EQ(r->status, 422) << r->body;
  req["targets"] = {{16, 31, 16}};
  r = s.postJson("/v1/lightning", req);
  ASSERT_EQ(r->status, 200) << r->body;
  const json j = json::parse(r->body);
  for (size_t i = 0; i < j["cells"].size(); i += 3) {
    const double dx = j["cells"][i].get<int>() + 0.5 - 16, dy = j["cells"][i + 1].get<int>() + 0.5 - 16,
                 dz = j["cells"][i + 2].get<int>() + 0.5 - 16;
    EXPECT_GT(std::sqrt(dx * dx + dy * dy + dz * dz), 5.0) << "inside the sphere's shell";
  }
}

TEST(LightningApi, VolumeProblemsNameTheField) {
  TestServer s;
  auto problem = [&](json req, int status, const std::string& pointer) {
    auto r = s.postJson("/v1/lightning", req);
    ASSERT_EQ(r->status, status) << r->body;
    EXPECT_EQ(json::parse(r->body)["errors"][0]["pointer"], pointer) << r->body;
  };
  json req = volumeRequest();
  req["start"] = {16, 0};
  problem(req, 400, "/start");
  req = volumeRequest();
  req["obstacles"] = {{"rects", {{0, 0, 4, 4}}}};
  problem(req, 400, "/obstacles/rects");
  req = request(32);
  req["world"] = {{"cellSize", 1}};
  problem(req, 400, "/world");
  req = request(32);
  req["obstacles"] = {{"boxes", {{0, 0, 0, 4, 4, 4}}}};
  problem(req, 400, "/obstacles/boxes");
  req = volumeRequest();
  req["obstacles"] = {{"mesh", {{"positions", {0, 0, 0, 1, 1, 1, 2, 2}}, {"indices", {0, 1, 2}}}}};
  problem(req, 400, "/obstacles/mesh/positions");
  req = volumeRequest();
  req["obstacles"] = {{"mesh", {{"positions", {0, 0, 0, 1, 1, 1, 2, 2, 2}}, {"indices", {0, 1, 3}}}}};
  problem(req, 400, "/obstacles/mesh/indices/2");
  req = volumeRequest();
  req["grid"] = {{"width", 80}, {"height", 80}, {"depth", 80}};
  req["method"] = "dbm";
  problem(req, 413, "/grid");
  req = volumeRequest();
  req["obstacles"] = {{"glb", base64Encode("not a glb")}};
  auto r = s.postJson("/v1/lightning", req);
  EXPECT_EQ(r->status, 400) << r->body;
  req = volumeRequest();
  req["method"] = "charges";
  problem(req, 400, "/method");
  req = volumeRequest();
  req["obstacles"] = {{"rows", {{{"y", 3}, {"runs", {{0, 4}}}}}}};
  problem(req, 400, "/obstacles/rows/0/z");
  req = request(32);
  req["obstacles"] = {{"rows", {{{"y", 3}, {"z", 1}, {"runs", {{0, 4}}}}}}};
  problem(req, 400, "/obstacles/rows/0/z");
}

// "targetRegion": the ground as one field; the answer names the struck cell, and include
// "shape" the bolt's cells, tips, branch points and D (the library's shapeOf).
TEST(LightningApi, TargetRegionStrikesTheGroundAndShapeDescribesTheBolt) {
  TestServer s;
  json req = {{"grid", {{"width", 48}, {"height", 48}}},
              {"start", {24, 0}},
              {"targetRegion", {{"rows", {{{"y", 47}, {"runs", {{0, 48}}}}}}}},
              {"include", {"shape", "cells", "tree"}},
              {"seed", 5}};
  for (const char* method : {"fast", "dbm", "charges"}) {
    req["method"] = method;
    auto r = s.postJson("/v1/lightning", req);
    ASSERT_EQ(r->status, 200) << r->body;
    const json j = json::parse(r->body);
    ASSERT_EQ(j["struck"].size(), 2u);
    EXPECT_EQ(j["struck"][1], 47);
    const size_t last = j["tree"]["mainChannel"].back();
    EXPECT_EQ(j["cells"][2 * last], j["struck"][0]);
    EXPECT_EQ(j["shape"]["cells"], j["cellCount"]);
    std::vector<int> children(j["cellCount"].get<size_t>(), 0);
    for (int parent : j["tree"]["parent"])
      if (parent >= 0) ++children[size_t(parent)];
    EXPECT_EQ(j["shape"]["tips"], std::count(children.begin(), children.end(), 0));
    EXPECT_EQ(j["shape"]["branchPoints"],
              std::count_if(children.begin(), children.end(), [](int c) { return c >= 2; }));
    EXPECT_GT(j["shape"]["fractalDimension"].get<double>(), 0.8);
  }
  json plain = request(48);  // without a region: no "struck"
  EXPECT_FALSE(json::parse(s.postJson("/v1/lightning", plain)->body).contains("struck"));

  json volume = volumeRequest();
  volume.erase("targets");
  volume["targetRegion"] = {{"boxes", {{0, 31, 0, 32, 1, 32}}}};
  auto r = s.postJson("/v1/lightning", volume);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(json::parse(r->body)["struck"][1], 31);

  auto problem = [&](json body, int status, const std::string& pointer) {
    auto p = s.postJson("/v1/lightning", body);
    ASSERT_EQ(p->status, status) << p->body;
    EXPECT_EQ(json::parse(p->body)["errors"][0]["pointer"], pointer) << p->body;
  };
  json bad = req;
  bad["targetRegion"] = {{"rows", {{{"y", 48}, {"runs", {{0, 48}}}}}}};
  problem(bad, 400, "/targetRegion/rows/0/y");
  bad["targetRegion"] = json::object();
  problem(bad, 400, "/targetRegion");
  bad["targetRegion"] = {{"boxes", {{0, 0, 0, 4, 4, 4}}}};
  problem(bad, 400, "/targetRegion/boxes");
  bad = req;
  bad["start"] = {24, 47};
  problem(bad, 422, "/start");
  bad = req;
  bad.erase("targetRegion");
  problem(bad, 400, "");  // neither targets nor a region: the schema's anyOf
}

// The reference's solves are the error stage, not compute: the fast method at 64^2 takes well
// under a millisecond, its converged DBM reference per step tens.
TEST(LightningApi, ReferenceSolvesAreTheErrorStageNotCompute) {
  TestServer s;
  json req = {{"grid", {{"width", 64}, {"height", 64}}},
              {"start", {32, 0}},
              {"targets", {{32, 63}}},
              {"include", {"error", "stats"}}};
  auto r = s.postJson("/v1/lightning", req);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const std::string timing = r->get_header_value("Server-Timing");
  const auto dur = [&](const std::string& name) {
    const size_t at = timing.find(name + ";dur=");
    return at == std::string::npos ? -1.0 : std::stod(timing.substr(at + name.size() + 5));
  };
  json j = json::parse(r->body);
  EXPECT_EQ(j["error"]["kind"], "measured");
  const std::string error = r->get_header_value("X-Effect-Error");
  EXPECT_EQ(error.rfind("meanTotalVariation=", 0), 0u) << error;
  EXPECT_NEAR(std::stod(error.substr(19)), j["error"]["meanTotalVariation"].get<double>(), 1e-3) << error;
  EXPECT_NE(error.find("kind=measured"), std::string::npos) << error;
  EXPECT_GT(dur("error"), 5 * dur("compute")) << timing;
  EXPECT_NEAR(j["stats"]["errorMs"].get<double>(), dur("error"), 1e-3) << timing;
}

}  // namespace
}  // namespace effectd::testing
