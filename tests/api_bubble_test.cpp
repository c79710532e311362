// POST /v1/bubble over HTTP: include-driven output, feature-driven shaders and uniforms,
// long times, errors.
#include <cmath>
#include <tuple>
#include <cstring>

#include <glm/geometric.hpp>
#include <glm/vec3.hpp>

#include "contract/codec.h"
#include "api/glb.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

TEST(BubbleApi, DefaultsAreTheFilmsUniformsAndShaderOnly) {
  TestServer s;
  auto r = s.postJson("/v1/bubble", json::object());
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("X-Effect-Method"), "thin-film");
  json j = json::parse(r->body);
  EXPECT_TRUE(j.contains("uniforms") && j.contains("shader"));
  EXPECT_FALSE(j.contains("mesh") || j.contains("thickness") || j.contains("gltf") || j.contains("stats"));
  const json& u = j["uniforms"];
  EXPECT_EQ(u["uThicknessRange"], json({0, 1000}));
  EXPECT_EQ(u["uLightCount"], 1);  // the default sun
  EXPECT_NEAR(glm::length(glm::dvec3(u["uLightDirection"][0][0], u["uLightDirection"][0][1],
                                     u["uLightDirection"][0][2])),
              1.0, 1e-12);
  // The relative wobble in object units: 3 % of the unit radius, 3 rad per unit.
  EXPECT_NEAR(u["uWobbleAmplitude"].get<double>(), 0.03, 1e-12);
  EXPECT_NEAR(u["uWobbleFrequency"].get<double>(), 3.0, 1e-12);
  for (const char* paper : {"uFilmTop", "uEta", "uRimPower", "uFlowPhase"}) EXPECT_FALSE(u.contains(paper)) << paper;
  EXPECT_EQ(j["shader"]["attributes"], json({"aPosition", "aNormal", "aUv"}));
  EXPECT_NE(j["shader"]["blend"].get<std::string>().find("ONE_MINUS_SRC_ALPHA"), std::string::npos);
  // A twice larger bubble wobbles twice as far at half the frequency per object unit.
  json big = json::parse(s.postJson("/v1/bubble", json{{"mesh", {{"radius", 2}}}, {"include", {"uniforms"}}})->body);
  EXPECT_NEAR(big["uniforms"]["uWobbleAmplitude"].get<double>(), 0.06, 1e-12);
  EXPECT_NEAR(big["uniforms"]["uWobbleFrequency"].get<double>(), 1.5, 1e-12);
  // The variant's error, said to be the report's estimate; the paper's model is further off.
  EXPECT_EQ(j["shadingError"]["kind"], "estimate");
  EXPECT_EQ(j["shadingError"]["variant"], "film + far side + highlight (default)");
  const double paper = json::parse(s.postJson("/v1/bubble", json{{"shading", "paper"}})->body)["shadingError"]["meanDeltaE"];
  EXPECT_GT(paper, 2 * j["shadingError"]["meanDeltaE"].get<double>());
  // Without the shader or its uniforms there is no shading to judge.
  EXPECT_FALSE(json::parse(s.postJson("/v1/bubble", json{{"include", {"mesh"}}})->body).contains("shadingError"));
}

TEST(BubbleApi, PaperModelUniformsAndShader) {
  TestServer s;
  auto r = s.postJson("/v1/bubble", json{{"shading", "paper"}});
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
              {"shading", "paper"},
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
  json a = json::parse(
      s.postJson("/v1/bubble", json{{"time", 1e9}, {"shading", "paper"}, {"include", {"uniforms"}}})->body);
  const long double pi = 3.14159265358979323846264338327950288L;
  double small = double(1e9L - std::floor(1e9L / pi) * pi);  // same wobble phase (period pi)
  json b = json::parse(
      s.postJson("/v1/bubble", json{{"time", small}, {"shading", "paper"}, {"include", {"uniforms"}}})->body);
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
      {"shading", "paper"},
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

// One wobble, not two: with the shader (its vertex stage wobbles by uWobble*) the mesh is the
// rest sphere; asked for alone it carries the wobble at `time`; the answer says which.
TEST(BubbleApi, MeshWithTheShaderIsTheRestShape) {
  TestServer s;
  auto radii = [](const json& mesh) {
    double lo = 1e9, hi = 0;
    const auto& p = mesh["positions"];
    for (size_t i = 0; i + 2 < p.size(); i += 3) {
      const double r = std::hypot(p[i].get<double>(), p[i + 1].get<double>(), p[i + 2].get<double>());
      lo = std::min(lo, r), hi = std::max(hi, r);
    }
    return std::pair{lo, hi};
  };
  json req = {{"time", 3}, {"mesh", {{"level", 2}}}, {"include", {"mesh", "shader", "uniforms"}}};
  auto r = s.postJson("/v1/bubble", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_FALSE(j["mesh"]["wobbled"].get<bool>());
  EXPECT_NE(j["shader"].dump().find("uWobbleAmplitude"), std::string::npos);
  auto [lo, hi] = radii(j["mesh"]);
  EXPECT_NEAR(lo, 1.0, 1e-6);
  EXPECT_NEAR(hi, 1.0, 1e-6);
  req["include"] = {"mesh"};
  j = json::parse(s.postJson("/v1/bubble", req)->body);
  EXPECT_TRUE(j["mesh"]["wobbled"].get<bool>());
  std::tie(lo, hi) = radii(j["mesh"]);
  EXPECT_GT(hi - lo, 0.01);
}

// The GLB's material: an iridescent film has air behind it (base ior 1, the film's n2 as
// iridescenceIor), so glTF viewers' iridescence shows over the whole face; without iridescence
// the base is the film's index.
TEST(BubbleApi, GlbBaseIorIsAirBehindAnIridescentFilm) {
  TestServer s;
  auto materialOf = [&](const json& req) {
    auto r = s.postJson("/v1/bubble", req);
    EXPECT_EQ(r->status, 200) << r->body.substr(0, 300);
    glb::Asset a;
    EXPECT_FALSE(glb::parse(r->body, a).has_value());
    return a.gltf["materials"][0]["extensions"];
  };
  json film = materialOf({{"format", "glb"}, {"mesh", {{"level", 1}}}});
  EXPECT_EQ(film["KHR_materials_ior"]["ior"].get<double>(), 1.0);
  EXPECT_NEAR(film["KHR_materials_iridescence"]["iridescenceIor"].get<double>(), 1.33, 1e-12);
  json plain = materialOf({{"format", "glb"}, {"shading", "paper"}, {"mesh", {{"level", 1}}}});
  EXPECT_FALSE(plain.contains("KHR_materials_iridescence"));
  EXPECT_NEAR(plain["KHR_materials_ior"]["ior"].get<double>(), 1.33, 1e-12);
  json j = json::parse(s.postJson("/v1/bubble", json{{"include", {"gltf"}}})->body);
  EXPECT_EQ(j["gltf"]["KHR_materials_ior"]["ior"].get<double>(), 1.0);
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
  // The paper's literal wobble (a = 1, k = 1) would fold the surface: refused, never clamped.
  p = expectProblem(s.postJson("/v1/bubble", json{{"params", {{"wobbleVariant", "paper"}, {"wobbleAmplitude", 1}}}}),
                    422);
  EXPECT_TRUE(hasPointer(p, "/params/wobbleAmplitude")) << p.dump();
  p = expectProblem(s.postJson("/v1/bubble", json{{"film", {{"swirl", 20}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/film/swirl")) << p.dump();
  p = expectProblem(s.postJson("/v1/bubble", json{{"lights", {{{"direction", {0, 0, 0}}}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/lights/0/direction")) << p.dump();
  p = expectProblem(s.postJson("/v1/bubble", json{{"film", {{"width", 4096}, {"height", 4096}}},
                                                  {"include", {"thickness"}}}),
                    413);
  EXPECT_TRUE(hasPointer(p, "/film/width")) << p.dump();
}

TEST(BubbleApi, ShadersForEveryEngine) {
  TestServer s;
  json req = {{"shader", {{"language", "spirv"}}}, {"include", {"shader"}}};
  auto r = s.postJson("/v1/bubble", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  auto bytes = base64Decode(j["shader"]["vertex"].get<std::string>());
  ASSERT_TRUE(bytes && bytes->size() >= 20);
  uint32_t magic;
  std::memcpy(&magic, bytes->data(), 4);
  EXPECT_EQ(magic, 0x07230203u);  // SPIR-V, little-endian words
  EXPECT_EQ(j["shader"]["entryPoints"]["vertex"], "main");
  bool block = false;
  for (const json& res : j["shader"]["resources"]) block |= res["kind"] == "uniformBlock" && res["name"] == "Uniforms";
  EXPECT_TRUE(block);
  EXPECT_FALSE(r->get_header_value("X-Shader-Cache").empty());
  if (r->get_header_value("X-Shader-Cache") == "miss") {
    EXPECT_NE(r->get_header_value("Server-Timing").find("shader;dur="), std::string::npos);
  }
  // A disabled feature leaves no trace in HLSL or MSL either; the same variant again is cached.
  for (const char* language : {"hlsl", "msl"}) {
    json q = {{"shader", {{"language", language}}},
              {"features", {{"highlight", false}, {"thickness", false}}},
              {"include", {"shader"}}};
    json a = json::parse(s.postJson("/v1/bubble", q)->body);
    const std::string code = a["shader"]["vertex"].get<std::string>() + a["shader"]["fragment"].get<std::string>();
    EXPECT_EQ(code.find("uLight"), std::string::npos) << language;
    EXPECT_EQ(code.find("uThicknessField"), std::string::npos) << language;
    EXPECT_NE(code.find("uThicknessNm"), std::string::npos) << language;
    q["time"] = 1;  // another answer, the same shader variant
    EXPECT_EQ(s.postJson("/v1/bubble", q)->get_header_value("X-Shader-Cache"), "hit") << language;
  }
  EXPECT_EQ(json::parse(s.postJson("/v1/bubble", json{{"shader", {{"language", "msl"}}}})->body)["shader"]["entryPoints"]
                ["fragment"],
            "main0");
}

TEST(BubbleApi, ThicknessTextureAndGlbCarryTheField) {
  TestServer s;
  json req = {{"film", {{"width", 32}, {"height", 16}}}, {"time", 3}, {"include", {"thickness", "gltf", "stats"}}};
  auto r = s.postJson("/v1/bubble", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  const json& t = j["thickness"];
  ASSERT_EQ(t["nm"].size(), 32u * 16);
  double lo = 1e9, hi = 0;
  for (double v : t["nm"]) lo = std::min(lo, v), hi = std::max(hi, v);
  EXPECT_LT(lo, 100.0);  // a thin top
  EXPECT_GT(hi, 600.0);  // a thick bottom
  EXPECT_TRUE(j["gltf"].contains("thicknessTexture"));
  EXPECT_EQ(j["gltf"]["KHR_materials_iridescence"]["iridescenceThicknessMaximum"], 1000.0);
  EXPECT_EQ(j["stats"][0]["method"], "drainage+swirl");
  req["film"]["encoding"] = "r32f";
  json b = json::parse(s.postJson("/v1/bubble", req)->body);
  auto bytes = base64Decode(b["thickness"]["data"].get<std::string>());
  ASSERT_TRUE(bytes);
  ASSERT_EQ(bytes->size(), 32u * 16 * 4);
  float first;
  std::memcpy(&first, bytes->data(), 4);
  EXPECT_FLOAT_EQ(first, t["nm"][0].get<float>());
  // The glb embeds the texture as KHR_materials_iridescence's thickness texture.
  auto g = s.postJson("/v1/bubble", json{{"format", "glb"}, {"film", {{"width", 32}, {"height", 16}}}});
  ASSERT_EQ(g->status, 200);
  EXPECT_NE(g->body.find("iridescenceThicknessTexture"), std::string::npos);
  EXPECT_NE(g->body.find("image/png"), std::string::npos);
}

}  // namespace
}  // namespace effectd::testing
