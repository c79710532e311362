// POST /v1/fog over HTTP.
#include <unistd.h>

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <fstream>

#include "contract/codec.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

TEST(FogApi, PaperExampleTable) {
  TestServer s;
  json req = {{"fog", {{"fogType", "DISTANCE_EXP2"}, {"color", {0.8, 0.8, 0.8}}, {"distanceCoefficient", 0.07}}},
              {"objectColors", {{0.7, 0.2, 0.1}}},
              {"table", {{"size", 17}, {"range", {0, 16}}}}};
  auto r = s.postJson("/v1/fog", req);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("X-Effect-Method"), "table-DISTANCE_EXP2");
  EXPECT_EQ(r->get_header_value("Server-Timing").rfind("compute;dur=", 0), 0u);
  json j = json::parse(r->body);
  const json& t = j["table"];
  EXPECT_EQ(t["size"], 17);
  ASSERT_EQ(t["factor"].size(), 17u);
  ASSERT_EQ(t["finalColors"][0].size(), 17u * 3);
  EXPECT_NEAR(t["finalColors"][0][0].get<double>(), 0.7, 1e-6);  // z = 0: object colour
  for (int c = 0; c < 3; ++c) EXPECT_NEAR(t["finalColors"][0][9 * 3 + c].get<double>(), 0.8, 1.0 / 255);  // z = 9
  EXPECT_GT(j["error"]["maxError"].get<double>(), 0.0);
  EXPECT_FALSE(j.contains("stats"));  // not asked for
}

TEST(FogApi, IdenticalRequestsGiveIdenticalBytes) {
  TestServer s;
  json req = {{"fog", {{"fogType", "HEIGHT"}, {"density", 0.2}, {"heightFalloff", 0.3}}},
              {"table", {{"size", 32}, {"elevations", 8}, {"cameraHeight", 2}}}};
  auto a = s.postJson("/v1/fog", req), b = s.postJson("/v1/fog", req);
  ASSERT_TRUE(a && b);
  ASSERT_EQ(a->status, 200) << a->body;
  EXPECT_EQ(a->body, b->body);
  json j = json::parse(a->body);
  EXPECT_EQ(j["table"]["factor"].size(), 32u * 8);
  EXPECT_EQ(j["table"]["elevations"], 8);
}

TEST(FogApi, Rgba8AndRgba16fEncodings) {
  TestServer s;
  json req = {{"fog", {{"fogType", "GL_EXP"}, {"color", {1, 0.5, 0}}, {"density", 0.1}}}, {"table", {{"size", 16}}}};
  req["table"]["encoding"] = "rgba8";
  auto r = s.postJson("/v1/fog", req);
  ASSERT_EQ(r->status, 200) << r->body;
  auto bytes = base64Decode(json::parse(r->body)["table"]["data"].get<std::string>());
  ASSERT_TRUE(bytes);
  ASSERT_EQ(bytes->size(), 16u * 4);
  EXPECT_EQ(uint8_t((*bytes)[3]), 255);  // d = 0: f = 1
  EXPECT_EQ(uint8_t((*bytes)[0]), 0);    // no fog contribution yet
  req["table"]["encoding"] = "rgba16f";
  r = s.postJson("/v1/fog", req);
  bytes = base64Decode(json::parse(r->body)["table"]["data"].get<std::string>());
  ASSERT_EQ(bytes->size(), 16u * 8);
  uint16_t lastAlpha = uint16_t(uint8_t((*bytes)[15 * 8 + 6]) | uint8_t((*bytes)[15 * 8 + 7]) << 8);
  EXPECT_NEAR(halfToFloat(lastAlpha), 1.0 / 255, 1e-4);
}

TEST(FogApi, SmallestTableForAnError) {
  TestServer s;
  json req = {{"fog", {{"fogType", "GL_EXP2"}, {"density", 0.05}}}, {"table", {{"maxError", 1e-3}}}};
  auto r = s.postJson("/v1/fog", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_LE(j["table"]["maxError"].get<double>(), 1e-3);
  EXPECT_LT(j["table"]["size"].get<int>(), 256);
}

// A maxError no table within the size limit meets, and a default range beyond the contract's
// largest number: 422s whose messages carry the numbers (not "0.000000"), naming the field.
TEST(FogApi, UnreachableErrorAndRangeAre422WithTheirNumbers) {
  TestServer s;
  json req = {{"fog", {{"fogType", "HEIGHT"}, {"density", 0.05}}}, {"table", {{"maxError", 1e-15}}}};
  auto p = expectProblem(s.postJson("/v1/fog", req), 422);
  EXPECT_EQ(p["errors"][0]["pointer"], "/table/maxError");
  const std::string message = p["errors"][0]["message"];
  EXPECT_EQ(message.find("0.000000"), std::string::npos) << message;
  EXPECT_NE(message.find("1e-15"), std::string::npos) << message;
  // GL_EXP at density 1e-300 reaches 1/255 at 5.5e300, beyond what a request may send back.
  req = {{"fog", {{"fogType", "GL_EXP"}, {"density", 1e-300}}}, {"table", {{"size", 16}}}};
  p = expectProblem(s.postJson("/v1/fog", req), 422);
  EXPECT_EQ(p["errors"][0]["pointer"], "/table/range");
  req["table"]["range"] = {0, 1e300};
  auto r = s.postJson("/v1/fog", req);
  ASSERT_EQ(r->status, 200) << r->body;
}

TEST(FogApi, RegionsAndSamples) {
  TestServer s;
  json req = {{"fog", {{"fogType", "DISTANCE_EXP2"}, {"distanceCoefficient", 0.01}}},
              {"regions",
               {{{"box", {{"min", {10, -5, -5}}, {"max", {20, 5, 5}}}},
                 {"fog", {{"fogType", "DISTANCE_EXP2"}, {"distanceCoefficient", 0.1}}}}}},
              {"samples", {{"camera", {0, 0, 0}}, {"points", {{5, 0, 0}, {15, 0, 0}}}}},
              {"include", {"samples", "regionTables"}},
              {"table", {{"size", 8}}}};
  auto r = s.postJson("/v1/fog", req);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_FALSE(j.contains("table"));
  EXPECT_EQ(j["regionTables"].size(), 1u);
  EXPECT_EQ(j["samples"][0]["region"], -1);
  EXPECT_NEAR(j["samples"][0]["factor"].get<double>(), std::exp(-0.01 * 25), 1e-6);
  EXPECT_EQ(j["samples"][1]["region"], 0);
  EXPECT_NEAR(j["samples"][1]["factor"].get<double>(), std::exp(-0.1 * 225), 1e-6);
}

TEST(FogApi, StatsOnlyWhenAsked) {
  TestServer s;
  auto r = s.postJson("/v1/fog", json{{"fog", {{"visibilityRange", 10}}}, {"include", {"table", "stats"}}});
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  ASSERT_TRUE(j.contains("stats"));
  EXPECT_EQ(j["stats"][0]["method"], "table-LINEAR");
  EXPECT_TRUE(j["stats"][0].contains("elapsedMs"));
}

TEST(FogApi, BadFieldsAre400WithPointers) {
  TestServer s;
  auto p =
      expectProblem(s.postJson("/v1/fog", json{{"fog", {{"fogType", "GL_LINEAR"}, {"start", 5}, {"end", 5}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/end")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", json::object()}, {"regions", {{{"fog", json::object()}}}}}),
                    400);
  EXPECT_TRUE(hasPointer(p, "/regions/0")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", json::object()}, {"include", {"samples"}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/samples")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"visibilityRange", 5}}}, {"table", {{"range", {3, 1}}}}}),
                    400);
  EXPECT_TRUE(hasPointer(p, "/table/range/1")) << p;
  // No fogType means X3D LINEAR, which visibilityRange 0 (its default) turns off: the problem
  // names that field, not the table's range that no distance completes.
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"density", 0.1}}}}), 422);
  EXPECT_TRUE(hasPointer(p, "/fog/visibilityRange")) << p;
  // With a range the table of an off fog is all clear, as X3D says.
  auto r = s.postJson("/v1/fog", json{{"fog", json::object()}, {"table", {{"range", {0, 10}}, {"size", 4}}}});
  EXPECT_EQ(r->status, 200) << r->body;
}

TEST(FogApi, EngineTermsInTablesAndErrors) {
  TestServer s;
  json req = {{"fog",
               {{"fogType", "HEIGHT"},
                {"density", 0.01},
                {"startDistance", 4},
                {"maxOpacity", 0.8},
                {"cutoffDistance", 40},
                {"secondLayer", {{"density", 0.002}, {"heightFalloff", 0.05}, {"baseHeight", 3}}}}},
              {"table", {{"size", 33}, {"elevations", 5}}}};
  auto r = s.postJson("/v1/fog", req);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  json t = json::parse(r->body)["table"];
  EXPECT_EQ(t["cutoffDistance"], 40);
  EXPECT_EQ(t["range"][1], 40);
  for (const auto& w : t["factor"]) EXPECT_GE(w.get<double>(), 0.2 - 1e-6);
  EXPECT_EQ(t["factor"][0], 1.0);  // within the start distance: clear
  json plain = json::parse(s.postJson("/v1/fog", json{{"fog", {{"fogType", "GL_EXP"}}}})->body)["table"];
  EXPECT_FALSE(plain.contains("cutoffDistance"));
  auto p = expectProblem(
      s.postJson("/v1/fog", json{{"fog", {{"fogType", "GL_EXP"}, {"secondLayer", {{"density", 1}}}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/secondLayer")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"maxOpacity", 2}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/maxOpacity")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"cutoffDistance", 0}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/cutoffDistance")) << p;
}

TEST(FogApi, DirectionalGlowInTables) {
  TestServer s;
  json req = {{"fog", {{"fogType", "GL_EXP"}, {"density", 0.05}, {"directional", {{"g", 0.8}, {"startDistance", 5}}}}},
              {"table", {{"size", 17}}}};
  json t = json::parse(s.postJson("/v1/fog", req)->body)["table"];
  ASSERT_EQ(t["inscatter"].size(), 17u);
  EXPECT_EQ(t["inscatter"][0], 0.0);
  EXPECT_GT(t["inscatter"][16].get<double>(), 0.9);
  req["table"]["encoding"] = "rgba16f";
  t = json::parse(s.postJson("/v1/fog", req)->body)["table"];
  auto bytes = base64Decode(t["inscatterData"].get<std::string>());
  ASSERT_TRUE(bytes);
  EXPECT_EQ(bytes->size(), 17u * 2);
  auto p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"directional", {{"direction", {0, 0, 0}}}}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/directional/direction")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"directional", {{"g", 1}}}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/directional/g")) << p;
}

TEST(FogApi, AtmosphericTablesPerChannel) {
  TestServer s;
  json req = {{"fog",
               {{"fogType", "ATMOSPHERIC"},
                {"color", {1, 0.5, 0.25}},
                {"extinction", {0.1, 0.2, 0.3}},
                {"inscattering", {0.05, 0.1, 0.2}}}},
              {"table", {{"size", 5}, {"range", {0, 10}}}},
              {"objectColors", {{0.2, 0.4, 0.6}}}};
  json t = json::parse(s.postJson("/v1/fog", req)->body)["table"];
  ASSERT_EQ(t["transmittance"].size(), 15u);
  const double d = 10, tr = std::exp(-0.3 * d), sc = 0.25 * (1 - std::exp(-0.2 * d));
  EXPECT_NEAR(t["transmittance"][14].get<double>(), tr, 1e-6);
  EXPECT_NEAR(t["fogContribution"][14].get<double>(), sc, 1e-6);
  EXPECT_NEAR(t["finalColors"][0][14].get<double>(), 0.6 * tr + sc, 1e-6);
  req["table"]["encoding"] = "rgba16f";
  t = json::parse(s.postJson("/v1/fog", req)->body)["table"];
  EXPECT_EQ(base64Decode(t["transmittanceData"].get<std::string>())->size(), 5u * 4 * 2);
  req["include"] = {"samples"};
  req["samples"] = {{"camera", {0, 0, 0}}, {"points", {{0, 0, -10}}}};
  json sample = json::parse(s.postJson("/v1/fog", req)->body)["samples"][0];
  EXPECT_NEAR(sample["transmittance"][2].get<double>(), tr, 1e-6);
  EXPECT_NEAR(sample["fogColor"][2].get<double>(), sc, 1e-6);
  auto p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"fogType", "ATMOSPHERIC"}, {"extinction", {0, -1, 0}}}}}),
                         400);
  EXPECT_TRUE(hasPointer(p, "/fog/extinction/1")) << p;
}

TEST(FogApi, TableOverTheLimitIs413) {
  Config c = TestServer::quietConfig();
  c.limits.maxTableSize = 1000;
  TestServer s(c);
  auto p =
      expectProblem(s.postJson("/v1/fog", json{{"fog", {{"visibilityRange", 5}}}, {"table", {{"size", 1001}}}}), 413);
  EXPECT_TRUE(hasPointer(p, "/table/size")) << p;
  EXPECT_NE(p["detail"].get<std::string>().find("--max-table-size"), std::string::npos) << p;  // the flag to raise
}

// The fog function for an engine's own shader, per fog type and with regions, in every
// language: the GLSL snippet holds only the used type's formula; SPIR-V passes spirv-val; HLSL
// compiles in glslang's HLSL front end.
bool toolAccepts(const std::string& command, const std::string& bytes, const std::string& suffix) {
  const std::string path = "/tmp/effectd_fog_" + std::to_string(::getpid()) + suffix;
  std::ofstream(path, std::ios::binary) << bytes;
  const bool ok = std::system((command + " " + path + " > /dev/null 2>&1").c_str()) == 0;
  std::remove(path.c_str());
  return ok;
}

TEST(FogApi, ShaderFunctionForEveryTypeInEveryLanguage) {
  TestServer s;
  for (const char* type : {"LINEAR", "EXPONENTIAL", "GL_LINEAR", "GL_EXP", "GL_EXP2", "DISTANCE_EXP2",
                           "DISTANCE_GAUSSIAN", "HEIGHT", "ATMOSPHERIC"}) {
    for (bool withRegions : {false, true}) {
      json body = {{"fog", {{"fogType", type}, {"density", 0.05}, {"visibilityRange", 30}}},
                   {"include", {"shader"}},
                   {"shader", {{"camera", {0, 1.7, 0}}}}};
      if (withRegions) {  // and the engine terms, so that every language compiles them too
        body["fog"]["startDistance"] = 2;
        body["fog"]["maxOpacity"] = 0.9;
        body["fog"]["cutoffDistance"] = 500;
        if (std::string(type) == "HEIGHT") body["fog"]["secondLayer"] = {{"density", 0.01}};
        body["fog"]["directional"] = {{"g", 0.6}};
      }
      if (withRegions)
        body["regions"] = {{{"sphere", {{"center", {0, 0, -10}}, {"radius", 3}}}, {"fog", {{"fogType", "GL_EXP"}}}}};
      auto r = s.postJson("/v1/fog", body);
      ASSERT_EQ(r->status, 200) << r->body;
      json j = json::parse(r->body);
      const std::string glsl = j["shader"]["code"];
      EXPECT_NE(glsl.find("vec3 applyFog(vec3 rgb, vec3 world)"), std::string::npos);
      EXPECT_EQ(glsl.find("fogLogG") != std::string::npos, std::string(type) == "HEIGHT") << type;
      EXPECT_EQ(j["shader"]["uniforms"].contains("uRegionLo"), withRegions);
      EXPECT_EQ(j["shader"]["uniforms"].contains("uFogEngine"), withRegions);  // only what the fog uses
      EXPECT_EQ(j["shader"]["uniforms"].contains("uFogLayer2"), withRegions && std::string(type) == "HEIGHT");
      EXPECT_EQ(j["shader"]["uniforms"]["uFogCamera"]["values"], json({0, 1.7, 0}));
      body["shader"]["language"] = "spirv";
      json spirv = json::parse(s.postJson("/v1/fog", body)->body);
      auto words = base64Decode(spirv["shader"]["code"].get<std::string>());
      ASSERT_TRUE(words);
      EXPECT_TRUE(toolAccepts("spirv-val --target-env vulkan1.0", *words, ".spv")) << type;
      body["shader"]["language"] = "hlsl";
      json hlsl = json::parse(s.postJson("/v1/fog", body)->body);
      EXPECT_NE(hlsl["shader"]["code"].get<std::string>().find("applyFog"), std::string::npos);
      EXPECT_TRUE(toolAccepts("glslangValidator -V -o /dev/null -D -e main -S frag", hlsl["shader"]["code"], ".hlsl"))
          << type << hlsl["shader"]["code"].get<std::string>();
    }
  }
}

// The engines' conventions in the shader: each slot's own function, valid SPIR-V and HLSL, the
// convention in uFogEngine.w; an effectd region beside them keeps effectd's formula.
TEST(FogApi, ShaderFunctionForEachConvention) {
  TestServer s;
  for (const char* convention : {"filament", "unreal"}) {
    json body = {
        {"fog",
         {{"fogType", "HEIGHT"},
          {"convention", convention},
          {"density", 0.05},
          {"startDistance", 2},
          {"directional", {{"exponent", 8}, {"startDistance", 10}}}}},
        {"regions", {{{"sphere", {{"center", {0, 0, -10}}, {"radius", 3}}}, {"fog", {{"fogType", "HEIGHT"}}}}}},
        {"include", {"shader"}}};
    if (std::string(convention) == "unreal") body["fog"]["secondLayer"] = {{"density", 0.01}};
    auto r = s.postJson("/v1/fog", body);
    ASSERT_EQ(r->status, 200) << r->body;
    json j = json::parse(r->body);
    const std::string glsl = j["shader"]["code"];
    const bool filament = std::string(convention) == "filament";
    EXPECT_EQ(glsl.find("fogFilament") != std::string::npos, filament) << convention;
    EXPECT_EQ(glsl.find("fogUnreal") != std::string::npos, !filament) << convention;
    EXPECT_EQ(j["shader"]["uniforms"]["uFogEngine"]["values"][3], filament ? 1 : 2);
    EXPECT_EQ(j["shader"]["uniforms"]["uFogEngine"]["values"][7], 0);  // the region: effectd
    body["shader"] = {{"language", "spirv"}};
    auto words = base64Decode(json::parse(s.postJson("/v1/fog", body)->body)["shader"]["code"].get<std::string>());
    ASSERT_TRUE(words);
    EXPECT_TRUE(toolAccepts("spirv-val --target-env vulkan1.0", *words, ".spv")) << convention;
    body["shader"]["language"] = "hlsl";
    json hlsl = json::parse(s.postJson("/v1/fog", body)->body);
    EXPECT_TRUE(toolAccepts("glslangValidator -V -o /dev/null -D -e main -S frag", hlsl["shader"]["code"], ".hlsl"))
        << convention << hlsl["shader"]["code"].get<std::string>();
  }
}

// The error pass is its own Server-Timing stage and a choice: a HEIGHT table measured (error
// stage, kind measured) and not (no error stage, kind estimate, the same table).
double stage(const std::string& timing, const std::string& name) {
  const size_t at = timing.find(name + ";dur=");
  return at == std::string::npos ? -1 : std::stod(timing.substr(at + name.size() + 5));
}

TEST(FogApi, ErrorMeasurementIsAStageAndAChoice) {
  TestServer s;
  json req = {{"fog", {{"fogType", "HEIGHT"}, {"density", 0.05}, {"heightFalloff", 0.2}}},
              {"table", {{"size", 128}, {"cameraHeight", 2}}}};
  auto measured = s.postJson("/v1/fog", req);
  req["table"]["measureError"] = false;
  auto estimated = s.postJson("/v1/fog", req);
  ASSERT_TRUE(measured && estimated);
  ASSERT_EQ(measured->status, 200) << measured->body;
  ASSERT_EQ(estimated->status, 200) << estimated->body;
  const std::string tm = measured->get_header_value("Server-Timing"), te = estimated->get_header_value("Server-Timing");
  EXPECT_GT(stage(tm, "error"), stage(tm, "compute")) << tm;  // 8 evaluations an entry against 1
  EXPECT_EQ(stage(te, "error"), -1) << te;
  json a = json::parse(measured->body), b = json::parse(estimated->body);
  EXPECT_EQ(a["table"]["factor"], b["table"]["factor"]);
  EXPECT_EQ(a["error"]["kind"], "measured");
  EXPECT_EQ(b["error"]["kind"], "estimate");
  // The estimate (second differences / 8) is of the measured error's order.
  const double m = a["error"]["maxError"].get<double>(), e = b["error"]["maxError"].get<double>();
  EXPECT_GT(e, m / 10) << m << " " << e;
  EXPECT_LT(e, m * 10) << m << " " << e;
}

}  // namespace
}  // namespace effectd::testing
