// POST /v1/lightning over HTTP.
#include <effects/common.h>

#include "codec.h"
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
  for (const char* absent : {"cells", "tree", "stats", "error", "fractalDimension", "guide"}) EXPECT_FALSE(j.contains(absent)) << absent;
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

}  // namespace
}  // namespace effectd::testing
