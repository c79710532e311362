// POST /v1/bubble over HTTP: include-driven output, feature-driven shaders and uniforms,
// long times, errors.
#include <cmath>

#include "codec.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

TEST(BubbleApi, DefaultsAreUniformsAndShaderOnly) {
  TestServer s;
  auto r = s.postJson("/v1/bubble", json::object());
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("X-Effect-Method"), "seed000");
  json j = json::parse(r->body);
  EXPECT_TRUE(j.contains("uniforms") && j.contains("shader"));
  EXPECT_FALSE(j.contains("mesh") || j.contains("thinFilm") || j.contains("gltf") || j.contains("stats"));
  EXPECT_EQ(j["uniforms"]["uFilmTop"], 1.0);  // t = 0 (eqn 3)
  EXPECT_EQ(j["uniforms"]["uFilmBottom"], 0.1);
  EXPECT_NEAR(j["uniforms"]["uEta"].get<double>(), 1 / 1.33, 1e-12);
  EXPECT_FALSE(j["uniforms"].contains("uThickness"));  // iridescence is off by default
}

TEST(BubbleApi, DisabledFeaturesLeaveNoUniformsOrCode) {
  TestServer s;
  json req = {{"features", {{"refraction", false}, {"wobble", false}, {"textureFlow", false}}},
              {"shader", {{"language", "glsl-330"}}}};
  json j = json::parse(s.postJson("/v1/bubble", req)->body);
  for (const char* gone : {"uEta", "uFilmBottom", "uWobblePhase", "uFlowPhase"}) {
    EXPECT_FALSE(j["uniforms"].contains(gone)) << gone;
    EXPECT_EQ((j["shader"]["vertex"].get<std::string>() + j["shader"]["fragment"].get<std::string>()).find(gone),
              std::string::npos)
        << gone;
  }
  EXPECT_EQ(j["shader"]["language"], "glsl-330");
  EXPECT_EQ(j["shader"]["vertex"].get<std::string>().rfind("#version 330 core", 0), 0u);
  EXPECT_FALSE(j["uniforms"].contains("flowOffset"));
}

TEST(BubbleApi, HugeTimeGivesTheReducedPhases) {
  TestServer s;
  json a = json::parse(s.postJson("/v1/bubble", json{{"time", 1e9}, {"include", {"uniforms"}}})->body);
  const long double pi = 3.14159265358979323846264338327950288L;
  double small = double(1e9L - std::floor(1e9L / pi) * pi);  // same wobble phase (period pi)
  json b = json::parse(s.postJson("/v1/bubble", json{{"time", small}, {"include", {"uniforms"}}})->body);
  EXPECT_NEAR(a["uniforms"]["uWobblePhase"].get<double>(), b["uniforms"]["uWobblePhase"].get<double>(), 1e-6);
  EXPECT_GE(a["uniforms"]["uFlowPhase"].get<double>(), 0.0);
  EXPECT_LT(a["uniforms"]["uFlowPhase"].get<double>(), 2 * M_PI);
}

TEST(BubbleApi, MeshThinFilmGltfAndMotion) {
  TestServer s;
  json req = {
      {"mesh", {{"level", 2}}},
      {"camera", {0, 0, 4}},
      {"motion", {{"from", {0, 0, 0}}, {"to", {2, 0, 0}}, {"s", 0.25}}},
      {"features", {{"iridescence", true}}},
      {"thinFilm",
       {{"width", 16}, {"height", 8}, {"wavelengths", 8}, {"thicknessRange", {100, 700}}, {"encoding", "rgba16f"}}},
      {"include", {"mesh", "thinFilm", "gltf", "uniforms", "stats"}}};
  auto r = s.postJson("/v1/bubble", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_EQ(j["position"], json({0.5, 0.0, 0.0}));
  const json& m = j["mesh"];
  size_t n = m["vertexCount"].get<size_t>();
  EXPECT_EQ(m["indices"].size(), 320u * 3);
  EXPECT_EQ(m["tangents"].size(), n * 4);
  EXPECT_EQ(m["finalVectors"].size(), n * 3);
  EXPECT_EQ(m["rim"].size(), n);
  auto bytes = base64Decode(j["thinFilm"]["data"].get<std::string>());
  ASSERT_TRUE(bytes);
  EXPECT_EQ(bytes->size(), 16u * 8 * 8);
  EXPECT_GT(j["thinFilm"]["meanDeltaE"].get<double>(), 0.0);
  EXPECT_EQ(j["gltf"]["KHR_materials_iridescence"]["iridescenceThicknessMaximum"], 700.0);
  EXPECT_TRUE(j["uniforms"].contains("uThickness"));
  EXPECT_FALSE(j.contains("shader"));
  EXPECT_EQ(j["stats"].size(), 2u);
}

TEST(BubbleApi, BadInputNamesTheField) {
  TestServer s;
  json p = expectProblem(s.postJson("/v1/bubble", json{{"mesh", {{"level", 9}}}, {"include", {"mesh"}}}),
                         400);  // the schema says at most 7
  EXPECT_TRUE(hasPointer(p, "/mesh/level")) << p.dump();
  p = expectProblem(s.postJson("/v1/bubble", json{{"params", {{"n2", 0.5}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/params/n2")) << p.dump();
  p = expectProblem(
      s.postJson("/v1/bubble", json{{"thinFilm", {{"thicknessRange", {500, 100}}}}, {"include", {"thinFilm"}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/thinFilm/thicknessRange")) << p.dump();
  p = expectProblem(s.postJson("/v1/bubble", json{{"time", 1e300}}), 400);
  EXPECT_TRUE(hasPointer(p, "/time")) << p.dump();
}

}  // namespace
}  // namespace effectd::testing
