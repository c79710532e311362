// HTTP as clients meet it, measured from the client's side of a real socket: keep-alive
// latency, content negotiation, CORS, the response cache, the memory budget.
#include <zlib.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "contract/config.h"
#include "http/encoding.h"
#include "contract/json_writer.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

double medianMs(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v[v.size() / 2];
}

// cpp-httplib sends headers and body in two writes; with Nagle on, the body waited for the
// client's delayed ACK (~44 ms per request after the first). TCP_NODELAY removes the stall.
TEST(Http, KeepAliveHasNoNagleStall) {
  TestServer s;
  const std::string fog = R"({"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":256}})";
  const std::vector<std::string> requests = {
      "GET /healthz HTTP/1.1\r\nHost: t\r\n\r\n",
      "POST /v1/fog HTTP/1.1\r\nHost: t\r\nContent-Type: application/json\r\nContent-Length: " +
          std::to_string(fog.size()) + "\r\n\r\n" + fog};
  for (const auto& request : requests) {
    KeepAlive c(s.port());
    ASSERT_TRUE(c.ok());
    ASSERT_NE(c.exchange(request).find("HTTP/1.1 200"), std::string::npos);  // warm
    std::vector<double> ms;
    for (int i = 0; i < 25; ++i) {
      auto t0 = std::chrono::steady_clock::now();
      std::string reply = c.exchange(request);
      ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
      ASSERT_NE(reply.find("HTTP/1.1 200"), std::string::npos) << reply;
    }
    EXPECT_LE(medianMs(ms), 2.0) << request.substr(0, request.find('\r'));
  }
}

std::string gunzip(const std::string& in) {
  z_stream z{};
  inflateInit2(&z, 15 + 16);
  std::string out(in.size() * 20 + 1024, '\0');
  z.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(in.data()));
  z.avail_in = uInt(in.size());
  z.next_out = reinterpret_cast<Bytef*>(out.data());
  z.avail_out = uInt(out.size());
  int rc = inflate(&z, Z_FINISH);
  out.resize(z.total_out);
  inflateEnd(&z);
  return rc == Z_STREAM_END ? out : "";
}

TEST(Http, NegotiatesContentCodingsWithQValues) {
  EXPECT_EQ(negotiate(""), Coding::kIdentity);
  EXPECT_EQ(negotiate("gzip"), Coding::kGzip);
  EXPECT_EQ(negotiate("gzip, deflate, br"), Coding::kBrotli);
  EXPECT_EQ(negotiate("gzip;q=0"), Coding::kIdentity) << "q=0 refuses";
  EXPECT_EQ(negotiate("gzip;q=0, br;q=0"), Coding::kIdentity);
  EXPECT_EQ(negotiate("br;q=0.5, gzip"), Coding::kGzip);
  EXPECT_EQ(negotiate("GZIP;Q=1"), Coding::kGzip);
  EXPECT_EQ(negotiate("*"), Coding::kBrotli);
  EXPECT_EQ(negotiate("*;q=0, gzip"), Coding::kGzip);
  EXPECT_EQ(negotiate("gzip;q=0.2, identity;q=0.5"), Coding::kIdentity);
  EXPECT_EQ(negotiate("gzip;q=garbage"), Coding::kIdentity);
}

TEST(Http, EachCodingIsItsOwnRepresentation) {
  TestServer s;
  const std::string body = R"({"fog":{"fogType":"GL_EXP2","density":0.05},"table":{"size":256}})";
  auto post = [&](httplib::Headers h) {
    auto c = s.client();
    c.set_decompress(false);  // look at the bytes on the wire
    auto r = c.Post("/v1/fog", h, body, "application/json");
    if (!r) ADD_FAILURE() << "no answer: " << httplib::to_string(r.error());
    return r;
  };
  auto plain = post({});
  ASSERT_TRUE(plain);
  ASSERT_EQ(plain->status, 200);
  EXPECT_FALSE(plain->has_header("Content-Encoding"));
  EXPECT_EQ(plain->get_header_value("Vary"), "Accept-Encoding");
  auto refused = post({{"Accept-Encoding", "gzip;q=0"}});
  EXPECT_FALSE(refused->has_header("Content-Encoding")) << "gzip;q=0 refuses gzip";
  EXPECT_EQ(refused->body, plain->body);
  EXPECT_EQ(refused->get_header_value("ETag"), plain->get_header_value("ETag"));

  auto gz = post({{"Accept-Encoding", "gzip, br;q=0"}});
  ASSERT_EQ(gz->status, 200);
  EXPECT_EQ(gz->get_header_value("Content-Encoding"), "gzip");
  EXPECT_EQ(gz->get_header_value("Vary"), "Accept-Encoding");
  EXPECT_LT(gz->body.size(), plain->body.size());
  EXPECT_EQ(gunzip(gz->body), plain->body);
  const std::string gzTag = gz->get_header_value("ETag");
  EXPECT_NE(gzTag, plain->get_header_value("ETag")) << "a strong ETag names one representation";
  auto br = post({{"Accept-Encoding", "br"}});
  EXPECT_EQ(br->get_header_value("Content-Encoding"), "br");
  EXPECT_NE(br->get_header_value("ETag"), gzTag);

  // If-None-Match compares with the representation this request would get.
  EXPECT_EQ(post({{"Accept-Encoding", "gzip"}, {"If-None-Match", gzTag}})->status, 304);
  EXPECT_EQ(post({{"If-None-Match", gzTag}})->status, 200);
  EXPECT_EQ(post({{"If-None-Match", plain->get_header_value("ETag")}})->status, 304);
  // Documents without an ETag are encoded too.
  auto raw = s.client();
  raw.set_decompress(false);
  auto yaml = raw.Get("/v1/openapi.yaml", httplib::Headers{{"Accept-Encoding", "gzip"}});
  ASSERT_TRUE(yaml) << httplib::to_string(yaml.error());
  EXPECT_EQ(yaml->get_header_value("Content-Encoding"), "gzip");
}

TEST(Http, RepeatsComeFromTheResponseCache) {
  TestServer s;
  const std::string body = R"({"fog":{"fogType":"GL_EXP","density":0.07},"table":{"size":64}})";
  auto a = s.postJson("/v1/fog", body);
  ASSERT_EQ(a->status, 200);
  EXPECT_NE(a->get_header_value("Server-Timing").find("compute"), std::string::npos);
  auto b = s.postJson("/v1/fog", body);
  EXPECT_EQ(b->get_header_value("Server-Timing"), "cache;desc=\"hit\"");
  EXPECT_EQ(b->body, a->body);
  EXPECT_EQ(b->get_header_value("ETag"), a->get_header_value("ETag"));
  EXPECT_EQ(b->get_header_value("X-Effect-Method"), a->get_header_value("X-Effect-Method"));
  // Another spelling of the same request: found by its ETag.
  auto c =
      s.postJson("/v1/fog", std::string(R"({ "table": {"size": 64}, "fog": {"density": 0.07, "fogType": "GL_EXP"} })"));
  EXPECT_EQ(c->get_header_value("Server-Timing"), "cache;desc=\"hit\"");
  EXPECT_EQ(c->body, a->body);
  // Timings in the body are never cached.
  auto d = s.postJson("/v1/fog", std::string(R"({"fog":{"fogType":"GL_EXP"},"include":["table","stats"]})"));
  auto e = s.postJson("/v1/fog", std::string(R"({"fog":{"fogType":"GL_EXP"},"include":["table","stats"]})"));
  EXPECT_EQ(e->get_header_value("Server-Timing").find("cache"), std::string::npos);
  auto m = s.client().Get("/metrics");
  EXPECT_NE(m->body.find("effectd_response_cache_hits_total 2\n"), std::string::npos) << m->body;

  Config off = TestServer::quietConfig();
  off.responseCacheMb = 0;
  TestServer uncached(off);
  uncached.postJson("/v1/fog", body);
  EXPECT_EQ(uncached.postJson("/v1/fog", body)->get_header_value("Server-Timing").find("cache"), std::string::npos);
}

TEST(Http, CorsForConfiguredOrigins) {
  const std::string body = R"({"fog":{"fogType":"GL_EXP"}})";
  {
    TestServer closed;  // default: no CORS headers for anyone
    auto r = closed.client().Post("/v1/fog", {{"Origin", "https://game.example"}}, body, "application/json");
    EXPECT_FALSE(r->has_header("Access-Control-Allow-Origin"));
  }
  Config c = TestServer::quietConfig();
  c.corsOrigins = {"https://game.example"};
  TestServer s(c);
  auto r = s.client().Post("/v1/fog", {{"Origin", "https://game.example"}}, body, "application/json");
  ASSERT_EQ(r->status, 200);
  EXPECT_EQ(r->get_header_value("Access-Control-Allow-Origin"), "https://game.example");
  const std::string exposed = r->get_header_value("Access-Control-Expose-Headers");
  for (const char* h : {"ETag", "Server-Timing", "X-Request-ID", "X-Effect-Method"})
    EXPECT_NE(exposed.find(h), std::string::npos) << h;
  EXPECT_EQ(r->get_header_value("Vary"), "Accept-Encoding, Origin");
  auto other = s.client().Post("/v1/fog", {{"Origin", "https://evil.example"}}, body, "application/json");
  EXPECT_FALSE(other->has_header("Access-Control-Allow-Origin"));
  // Problems carry it too, or a browser could not read why it failed.
  auto bad = s.client().Post("/v1/fog", {{"Origin", "https://game.example"}}, "{}", "application/json");
  EXPECT_EQ(bad->status, 400);
  EXPECT_EQ(bad->get_header_value("Access-Control-Allow-Origin"), "https://game.example");
  // The preflight.
  auto pre = s.client().Options("/v1/render", {{"Origin", "https://game.example"},
                                               {"Access-Control-Request-Method", "POST"},
                                               {"Access-Control-Request-Headers", "content-type"}});
  ASSERT_TRUE(pre);
  EXPECT_EQ(pre->status, 204);
  EXPECT_EQ(pre->get_header_value("Access-Control-Allow-Origin"), "https://game.example");
  EXPECT_EQ(pre->get_header_value("Access-Control-Allow-Methods"), "POST, GET, HEAD");
  EXPECT_NE(pre->get_header_value("Access-Control-Allow-Headers").find("Content-Type"), std::string::npos);
  EXPECT_NE(pre->get_header_value("Access-Control-Allow-Headers").find("Authorization"), std::string::npos);  // API keys
  EXPECT_EQ(s.client().Options("/healthz")->get_header_value("Allow"), "GET, HEAD, OPTIONS");
}

TEST(Http, FloatsInTheirShortestForm) {
  using nlohmann::json;
  EXPECT_EQ(writeJson(json{0.7f, 0.2f, 1.0f, -0.5f}), "[0.7,0.2,1.0,-0.5]");
  EXPECT_EQ(writeJson(json{0.1, 1.0 / 3.0, 1e-300, 2.5e20}), "[0.1,0.3333333333333333,1e-300,2.5e+20]");
  EXPECT_EQ(writeJson(json{std::nan(""), HUGE_VAL}), "[null,null]");
  EXPECT_EQ(writeJson(json{{"a\"b", "caf\xc3\xa9\n"}, {"n", -3}, {"u", 7u}, {"t", true}, {"z", nullptr}}),
            R"({"a\"b":"café\n","n":-3,"t":true,"u":7,"z":null})");
  // Every float32 reads back to itself.
  for (float f : {0.7f, 1e-38f, 3.4028235e38f, 0.1f + 0.2f, 123456.79f}) {
    std::string text = writeJson(json(f));
    EXPECT_EQ(std::strtof(text.c_str(), nullptr), f) << text;
  }
  TestServer s;
  auto r = s.postJson(
      "/v1/fog", std::string(R"({"fog":{"fogType":"GL_EXP","density":0.1,"color":[0.7,0.2,0.1]},"table":{"size":4}})"));
  EXPECT_EQ(r->body.find("0.699999988"), std::string::npos) << r->body;
}

TEST(Http, HelpNamesTheRenderCommand) {
  EXPECT_NE(usage().find("effectd render SCENE.json -o OUT.png"), std::string::npos);
}

}  // namespace
}  // namespace effectd::testing
