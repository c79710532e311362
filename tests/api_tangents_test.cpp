// POST /v1/tangents over HTTP: JSON meshes, binary glTF in and out, errors.
#include <cmath>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>

#include "api/error_estimates.h"
#include "api/glb.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

json quadMesh() {
  return {{"positions", {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}},
          {"uvs", {0, 0, 1, 0, 1, 1, 0, 1}},
          {"indices", {0, 1, 2, 0, 2, 3}}};
}

TEST(TangentsApi, QuadDefaultsToMikkTSpace) {
  TestServer s;
  auto r = s.postJson("/v1/tangents", json{{"mesh", quadMesh()}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("X-Effect-Method"), "mikktspace");
  json j = json::parse(r->body);
  EXPECT_EQ(j["vertexCount"], 4);
  EXPECT_EQ(j["tangents"], json({1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0, 1.0, 0.0, 0.0, 1.0}));
  EXPECT_EQ(j["remap"], json({0, 1, 2, 3}));
  EXPECT_EQ(j["indices"], json({0, 1, 2, 0, 2, 3}));
  EXPECT_FALSE(j.contains("normals") || j.contains("stats") || j.contains("error"));  // not asked for
  EXPECT_EQ(r->get_header_value("X-Effect-Error").rfind("meanAngleDeg=0; kind=exact", 0), 0u);  // the reference
}

TEST(TangentsApi, TopLeftUvOriginNegatesW) {
  TestServer s;
  auto r = s.postJson("/v1/tangents", json{{"mesh", quadMesh()}, {"uvOrigin", "top-left"}, {"include", {"tangents"}}});
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_EQ(j["tangents"][3], -1.0);
  EXPECT_FALSE(j.contains("remap"));
}

TEST(TangentsApi, PerTriangleWithErrorAndFrames) {
  TestServer s;
  json mesh = quadMesh();
  mesh["positions"][8] = 0.5;  // lift a corner: the two triangles' frames now differ
  auto r = s.postJson("/v1/tangents", json{{"mesh", mesh},
                                           {"mode", "perTriangle"},
                                           {"include", {"tangents", "remap", "triangleFrames", "error", "stats"}}});
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_EQ(j["method"], "perTriangle");
  EXPECT_EQ(j["triangleFrames"]["w"], json({1.0, 1.0}));
  EXPECT_EQ(j["triangleFrames"]["tangents"].size(), 6u);
  EXPECT_GT(j["error"]["meanAngleDeg"].get<double>(), 0.0);
  EXPECT_EQ(j["error"]["reference"], "mikktspace");
  EXPECT_NE(r->get_header_value("X-Effect-Error").find("kind=measured"), std::string::npos);
  EXPECT_EQ(j["stats"]["method"], "perTriangle");
  // Without include error: the report's figure for perTriangle, said to be an estimate.
  auto e = s.postJson("/v1/tangents", json{{"mesh", mesh}, {"mode", "perTriangle"}});
  char stated[64];  // the report's figure (its data, embedded) and limit
  std::snprintf(stated, sizeof stated, "meanAngleDeg=%.3g; limit=5; kind=estimate",
                effectd::tangentsErrorEstimate(effects::tangents::Mode::kPerTriangle).value);
  EXPECT_EQ(e->get_header_value("X-Effect-Error").rfind(stated, 0), 0u)
      << e->get_header_value("X-Effect-Error");
  EXPECT_GT(j["vertexCount"].get<int>(), 4);  // shared vertices split between the two flat frames
}

TEST(TangentsApi, PerVertexAverageNeverSplits) {
  TestServer s;
  json mesh = quadMesh();
  mesh["positions"][8] = 0.5;
  auto r = s.postJson("/v1/tangents", json{{"mesh", mesh}, {"mode", "perVertex"}, {"include", {"tangents", "error"}}});
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_EQ(j["method"], "perVertex");
  EXPECT_EQ(j["vertexCount"].get<int>(), 4);
  EXPECT_EQ(j["error"]["reference"], "mikktspace");
}

TEST(TangentsApi, BadMeshesNameTheField) {
  TestServer s;
  json mesh = quadMesh();
  mesh["indices"][4] = 17;
  json p = expectProblem(s.postJson("/v1/tangents", json{{"mesh", mesh}}), 400);
  EXPECT_TRUE(hasPointer(p, "/mesh/indices/4")) << p.dump();

  mesh = quadMesh();
  mesh["positions"][7] = 1e39;  // not a 32-bit float
  p = expectProblem(s.postJson("/v1/tangents", json{{"mesh", mesh}}), 400);
  EXPECT_TRUE(hasPointer(p, "/mesh/positions/7")) << p.dump();

  mesh = quadMesh();
  mesh["uvs"].erase(7);
  p = expectProblem(s.postJson("/v1/tangents", json{{"mesh", mesh}}), 400);
  EXPECT_TRUE(hasPointer(p, "/mesh/uvs")) << p.dump();

  mesh = quadMesh();
  mesh["normals"] = {0, 0, 1};
  p = expectProblem(s.postJson("/v1/tangents", json{{"mesh", mesh}}), 400);
  EXPECT_TRUE(hasPointer(p, "/mesh/normals")) << p.dump();

  Config c = TestServer::quietConfig();
  c.limits.maxMeshTriangles = 1;
  TestServer small(c);
  p = expectProblem(small.postJson("/v1/tangents", json{{"mesh", quadMesh()}}), 413);
  EXPECT_TRUE(hasPointer(p, "/mesh/indices")) << p.dump();
}

// A GLB with one quad primitive: POSITION + TEXCOORD_0, no NORMAL, 16-bit indices.
std::string quadGlb() {
  glb::Asset a;
  a.gltf = {{"asset", {{"version", "2.0"}}},
            {"buffers", json::array({json::object()})},
            {"bufferViews", json::array()},
            {"accessors", json::array()}};
  int pos = glb::addFloatAccessor(a, {0, 0, 0, 1, 0, 0, 1, 1, 0, 0, 1, 0}, 3, true);
  int uv = glb::addFloatAccessor(a, {0, 1, 1, 1, 1, 0, 0, 0}, 2, true);  // glTF: v down
  int idx = glb::addIndexAccessor(a, {0, 1, 2, 0, 2, 3});
  a.gltf["accessors"][size_t(pos)]["min"] = {0, 0, 0};
  a.gltf["accessors"][size_t(pos)]["max"] = {1, 1, 0};
  a.gltf["meshes"] = {{{"primitives", {{{"attributes", {{"POSITION", pos}, {"TEXCOORD_0", uv}}}, {"indices", idx}}}}}};
  return glb::serialize(a);
}

// A page on another origin can read every X- header the service sends (the tangents report of
// a GLB, an animation's frame count and rate, a flipbook's layout, the renderer's), not only the
// JSON answers' ones.
TEST(TangentsApi, EveryXHeaderIsExposedToAllowedOrigins) {
  Config c = TestServer::quietConfig();
  c.corsOrigins = {"https://game.example"};
  TestServer s(c);
  const httplib::Headers origin = {{"Origin", "https://game.example"}};
  auto scene = [](const char* format) {
    return json{{"width", 64},
                {"height", 64},
                {"frames", {{"count", 4}, {"fps", 8}, {"format", format}}},
                {"lightning", {{"grid", {{"width", 32}, {"height", 32}}}, {"start", {16, 0}}, {"targets", {{16, 31}}}}}}
        .dump();
  };
  std::vector<httplib::Result> answers;
  answers.push_back(s.client().Post("/v1/tangents", origin, quadGlb(), "model/gltf-binary"));
  answers.push_back(s.client().Post("/v1/render", origin, scene("gif"), "application/json"));
  answers.push_back(s.client().Post("/v1/render", origin, scene("flipbook"), "application/json"));
  answers.push_back(s.client().Post("/v1/fog", origin, R"({"fog":{"fogType":"GL_EXP"}})", "application/json"));
  std::set<std::string> seen;
  for (const auto& r : answers) {
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body.substr(0, 300);
    const std::string exposed = ", " + r->get_header_value("Access-Control-Expose-Headers") + ",";
    for (const auto& [name, value] : r->headers)
      if (name.rfind("X-", 0) == 0) {
        seen.insert(name);
        EXPECT_NE(exposed.find(", " + name + ","), std::string::npos) << name << " is not in" << exposed;
      }
  }
  for (const char* h : {"X-Tangents", "X-Frame-Count", "X-Frame-Rate", "X-Flipbook-Columns", "X-Flipbook-Rows"})
    EXPECT_TRUE(seen.count(h)) << h << " was not sent";
}

TEST(TangentsApi, GlbGetsTangentsAndFlatNormals) {
  TestServer s;
  auto r = s.client().Post("/v1/tangents", quadGlb(), "model/gltf-binary");
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "model/gltf-binary");
  glb::Asset out;
  ASSERT_FALSE(glb::parse(r->body, out).has_value());
  const json& attrs = out.gltf["meshes"][0]["primitives"][0]["attributes"];
  ASSERT_TRUE(attrs.contains("TANGENT") && attrs.contains("NORMAL")) << out.gltf.dump();
  std::vector<float> t, n, p;
  ASSERT_FALSE(glb::readFloats(out, attrs["TANGENT"].get<int>(), 4, t).has_value());
  ASSERT_FALSE(glb::readFloats(out, attrs["NORMAL"].get<int>(), 3, n).has_value());
  ASSERT_FALSE(glb::readFloats(out, attrs["POSITION"].get<int>(), 3, p).has_value());
  ASSERT_EQ(t.size() / 4, p.size() / 3);
  ASSERT_EQ(n.size() / 3, p.size() / 3);
  EXPECT_EQ(p.size() / 3, 6u);  // flat normals: one vertex per corner (glTF's rule without NORMAL)
  for (size_t v = 0; v < t.size() / 4; ++v) {
    EXPECT_NEAR(t[4 * v], 1.0f, 1e-6);
    EXPECT_EQ(t[4 * v + 3], 1.0f);  // UV area < 0 in MikkTSpace terms (v runs down), w negated for glTF
    EXPECT_NEAR(n[3 * v + 2], 1.0f, 1e-6);
  }
  std::vector<uint32_t> idx;
  ASSERT_FALSE(glb::readIndices(out, out.gltf["meshes"][0]["primitives"][0]["indices"].get<int>(), idx).has_value());
  EXPECT_EQ(idx.size(), 6u);
}

TEST(TangentsApi, RealGlbFromAssimpTestModels) {
  const char* path = "/usr/share/assimp/models/glTF2/BoxTextured-glTF-Binary/BoxTextured.glb";
  std::ifstream f(path, std::ios::binary);
  ASSERT_TRUE(f) << path << " missing: scripts/setup.sh installs assimp-testmodels";
  std::stringstream ss;
  ss << f.rdbuf();
  TestServer s;
  auto r = s.client().Post("/v1/tangents", ss.str(), "model/gltf-binary");
  ASSERT_EQ(r->status, 200) << r->body;
  glb::Asset in, out;
  ASSERT_FALSE(glb::parse(ss.str(), in).has_value());
  ASSERT_FALSE(glb::parse(r->body, out).has_value());
  EXPECT_EQ(out.gltf["images"], in.gltf["images"]);  // untouched
  EXPECT_EQ(out.gltf["materials"], in.gltf["materials"]);
  const json& attrs = out.gltf["meshes"][0]["primitives"][0]["attributes"];
  std::vector<float> t, n;
  ASSERT_FALSE(glb::readFloats(out, attrs["TANGENT"].get<int>(), 4, t).has_value());
  ASSERT_FALSE(glb::readFloats(out, attrs["NORMAL"].get<int>(), 3, n).has_value());
  ASSERT_EQ(t.size() / 4, n.size() / 3);
  for (size_t v = 0; v < n.size() / 3; ++v) {
    double dot = t[4 * v] * n[3 * v] + t[4 * v + 1] * n[3 * v + 1] + t[4 * v + 2] * n[3 * v + 2];
    EXPECT_LT(std::abs(dot), 1e-5);
    EXPECT_NEAR(std::hypot(t[4 * v], t[4 * v + 1], t[4 * v + 2]), 1.0, 1e-5);
  }
}

// The JSON chunk padded with zero bytes instead of spaces, as some exporters write it.
TEST(TangentsApi, GlbWithZeroPaddedJsonIsRead) {
  const std::string g = quadGlb();
  uint32_t jsonLength = 0;
  std::memcpy(&jsonLength, g.data() + 12, 4);
  std::string text = g.substr(20, jsonLength);
  while (!text.empty() && text.back() == ' ') text.pop_back();
  text += std::string(4 - text.size() % 4, '\0');
  const std::string rest = g.substr(20 + jsonLength);
  auto u32 = [](uint32_t v) { return std::string(reinterpret_cast<const char*>(&v), 4); };
  const std::string padded = "glTF" + u32(2) + u32(uint32_t(12 + 8 + text.size() + rest.size())) +
                             u32(uint32_t(text.size())) + "JSON" + text + rest;
  glb::Asset a;
  ASSERT_FALSE(glb::parse(padded, a).has_value());
  EXPECT_TRUE(a.gltf.contains("meshes"));
  TestServer s;
  auto r = s.client().Post("/v1/tangents", padded, "model/gltf-binary");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200) << r->body;
}

TEST(TangentsApi, BrokenGlbIsRefused) {
  TestServer s;
  expectProblem(s.client().Post("/v1/tangents", std::string("not a glb at all, just text"), "model/gltf-binary"), 400);
  std::string g = quadGlb();
  expectProblem(s.client().Post("/v1/tangents", g.substr(0, g.size() - 8), "model/gltf-binary"), 400);  // truncated
  // An accessor pointing past the binary chunk.
  glb::Asset a;
  ASSERT_FALSE(glb::parse(g, a).has_value());
  a.gltf["accessors"][0]["count"] = 1000000;
  json p = expectProblem(s.client().Post("/v1/tangents", glb::serialize(a), "model/gltf-binary"), 422);
  EXPECT_TRUE(hasPointer(p, "/accessors/0")) << p.dump();
  // A buffer with an external URI is never followed.
  ASSERT_FALSE(glb::parse(g, a).has_value());
  a.gltf["buffers"][0]["uri"] = "file:///etc/passwd";
  p = expectProblem(s.client().Post("/v1/tangents", glb::serialize(a), "model/gltf-binary"), 422);
  EXPECT_TRUE(hasPointer(p, "/buffers/0")) << p.dump();
  // Wrong JSON types inside the glTF.
  ASSERT_FALSE(glb::parse(g, a).has_value());
  a.gltf["meshes"][0]["primitives"][0]["attributes"]["POSITION"] = "zero";
  p = expectProblem(s.client().Post("/v1/tangents", glb::serialize(a), "model/gltf-binary"), 422);
  EXPECT_TRUE(hasPointer(p, "/meshes/0/primitives/0/attributes/POSITION")) << p.dump();
  // Numbers that are not glTF integers are named, never converted (5e26 to int is undefined).
  ASSERT_FALSE(glb::parse(g, a).has_value());
  a.gltf["accessors"][0]["componentType"] = 5e26;
  p = expectProblem(s.client().Post("/v1/tangents", glb::serialize(a), "model/gltf-binary"), 422);
  EXPECT_TRUE(hasPointer(p, "/accessors/0/componentType")) << p.dump();
  ASSERT_FALSE(glb::parse(g, a).has_value());
  a.gltf["accessors"][0]["count"] = -4;
  p = expectProblem(s.client().Post("/v1/tangents", glb::serialize(a), "model/gltf-binary"), 422);
  EXPECT_TRUE(hasPointer(p, "/accessors/0/count")) << p.dump();
  ASSERT_FALSE(glb::parse(g, a).has_value());
  a.gltf["meshes"][0]["primitives"][0]["mode"] = 4.5;
  p = expectProblem(s.client().Post("/v1/tangents", glb::serialize(a), "model/gltf-binary"), 422);
  EXPECT_TRUE(hasPointer(p, "/meshes/0/primitives/0/mode")) << p.dump();
}

}  // namespace
}  // namespace effectd::testing
