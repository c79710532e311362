// Facing the internet (server/http/access.h): answers by GET URL, cacheable; signed URLs; API
// keys with quotas.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cstdio>
#include <ctime>
#include <filesystem>
#include <fstream>
#include <string>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "contract/codec.h"
#include "http/url_signing.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

const json kFog = {{"fog", {{"fogType", "GL_EXP2"}, {"density", 0.05}}}, {"table", {{"size", 64}}}};

std::string url(const std::string& path, const json& body) { return path + "?r=" + base64UrlEncode(body.dump()); }

// A file under the test's temporary directory holding `text`.
std::string writeFile(const std::string& name, const std::string& text) {
  const auto path = std::filesystem::temp_directory_path() / ("effectd-urls-" + std::to_string(::getpid()) + "-" + name);
  std::ofstream(path) << text;
  return path.string();
}

// The problem document without what differs per request.
json problemOf(const std::string& body) {
  json p = json::parse(body);
  p.erase("requestId");
  p.erase("instance");
  return p;
}

TEST(Urls, GetAnswersWhatPostAnswersWithTheSameEtag) {
  TestServer s;
  const json bodies[][2] = {
      {"/v1/fog", kFog},
      {"/v1/lightning", {{"grid", {{"width", 48}, {"height", 48}}}, {"start", {24, 0}}, {"targets", {{24, 47}}}, {"seed", 3}}},
      {"/v1/bubble", {{"mesh", {{"level", 2}}}, {"include", {"mesh", "uniforms"}}}},
      {"/v1/scene", {{"fog", kFog}}},
  };
  for (const auto& [path, body] : bodies) {
    auto post = s.postJson(path.get<std::string>(), body);
    auto get = s.client().Get(url(path.get<std::string>(), body).c_str());
    ASSERT_TRUE(post && get) << path;
    EXPECT_EQ(post->status, 200) << path << post->body;
    EXPECT_EQ(get->status, 200) << path << get->body;
    EXPECT_EQ(get->body, post->body) << path;
    EXPECT_FALSE(get->get_header_value("ETag").empty()) << path;
    EXPECT_EQ(get->get_header_value("ETag"), post->get_header_value("ETag")) << path;
    EXPECT_EQ(get->get_header_value("Cache-Control"), "public, max-age=3600") << path;
    EXPECT_NE(get->get_header_value("Vary").find("Accept-Encoding"), std::string::npos) << path;
    // A conditional GET: 304, no body, the same validator.
    httplib::Headers h = {{"If-None-Match", get->get_header_value("ETag")}};
    auto again = s.client().Get(url(path.get<std::string>(), body).c_str(), h);
    ASSERT_TRUE(again);
    EXPECT_EQ(again->status, 304) << path;
    EXPECT_TRUE(again->body.empty());
  }
  // HEAD: the GET's headers.
  auto head = s.client().Head(url("/v1/fog", kFog).c_str());
  ASSERT_TRUE(head);
  EXPECT_EQ(head->status, 200);
  EXPECT_FALSE(head->get_header_value("ETag").empty());
}

TEST(Urls, GetGivesThePostsProblemsAndNeverCachesThem) {
  TestServer s;
  for (const json& bad : {json{{"fog", {{"fogType", "NOPE"}}}}, json{{"fog", {{"density", -1}}}},
                          json{{"fog", kFog["fog"]}, {"table", {{"size", 1}}}}}) {
    auto post = s.postJson("/v1/fog", bad);
    auto get = s.client().Get(url("/v1/fog", bad).c_str());
    ASSERT_TRUE(post && get);
    EXPECT_GE(post->status, 400);
    EXPECT_EQ(get->status, post->status) << bad;
    EXPECT_EQ(problemOf(get->body), problemOf(post->body)) << bad;
    EXPECT_EQ(get->get_header_value("Cache-Control"), "no-store");
  }
  // The URL itself: no r, r not base64url, a parameter GET does not take.
  for (const auto& [target, pointer] :
       {std::pair{"/v1/fog", "?r"}, std::pair{"/v1/fog?r=e3%2B0", "?r"}, std::pair{"/v1/fog?r=e30&size=4", "?size"}}) {
    auto r = s.client().Get(target);
    ASSERT_TRUE(r);
    EXPECT_EQ(r->status, 400) << target;
    EXPECT_EQ(json::parse(r->body)["errors"][0]["pointer"], pointer) << target << r->body;
  }
}

TEST(Urls, LimitsApplyToTheUrlAndTheDecodedBody) {
  Config c = TestServer::quietConfig();
  c.limits.maxUrlBytes = 512;
  c.limits.maxBodyBytes = 2048;
  c.cacheMaxAgeS = 60;
  TestServer s(c);
  json big = kFog;
  big["pad"] = std::string(600, 'x');  // the URL passes 512 bytes
  auto tooLong = s.client().Get(url("/v1/fog", big).c_str());
  ASSERT_TRUE(tooLong);
  EXPECT_EQ(tooLong->status, 414);
  EXPECT_NE(tooLong->body.find("--max-url-bytes"), std::string::npos);
  EXPECT_EQ(tooLong->get_header_value("Cache-Control"), "no-store");
  Config wide = c;
  wide.limits.maxUrlBytes = 8192;  // the most: cpp-httplib's compiled limit
  TestServer w(wide);
  json huge = kFog;
  huge["pad"] = std::string(9000, 'x');  // past cpp-httplib's own limit: its 414 is effectd's problem too
  auto past = w.client().Get(url("/v1/fog", huge).c_str());
  ASSERT_TRUE(past);
  EXPECT_EQ(past->status, 414);
  EXPECT_EQ(past->get_header_value("Cache-Control"), "no-store");
  EXPECT_NE(past->body.find("uri-too-long"), std::string::npos) << past->body;
  big["pad"] = std::string(3000, 'x');  // decodes to more than 2048 bytes
  auto tooBig = w.client().Get(url("/v1/fog", big).c_str());
  ASSERT_TRUE(tooBig);
  EXPECT_EQ(tooBig->status, 413);
  auto fine = s.client().Get(url("/v1/fog", kFog).c_str());
  ASSERT_TRUE(fine);
  EXPECT_EQ(fine->get_header_value("Cache-Control"), "public, max-age=60");  // --cache-max-age
}

TEST(Urls, SignedUrlsWithTwoKeysExpiryAndConstantTimeChecks) {
  Config c = TestServer::quietConfig();
  const std::string keyNew = "a-new-signing-key-0123", keyOld = "the-old-signing-key-456";
  c.urlSigningKeyFile = writeFile("sign", keyNew + "\n" + keyOld + "\n");
  TestServer s(c);
  const std::string target = url("/v1/fog", kFog);
  auto get = [&](const std::string& t) {
    auto r = s.client().Get(t.c_str());
    EXPECT_TRUE(r);
    return r;
  };
  // Either key of a rotation signs.
  for (const auto& key : {keyNew, keyOld}) {
    auto r = get(target + "&sig=" + UrlSigning::sign(key, target));
    EXPECT_EQ(r->status, 200) << r->body;
  }
  EXPECT_EQ(get(target)->status, 403);                                                       // unsigned
  EXPECT_EQ(get(target + "&sig=" + UrlSigning::sign("another-key-9999999", target))->status, 403);  // wrong key
  const std::string tampered = url("/v1/fog", json{{"fog", {{"fogType", "GL_EXP"}}}});
  EXPECT_EQ(get(tampered + "&sig=" + UrlSigning::sign(keyNew, target))->status, 403);       // another body
  // exp is signed: in the future it answers, cached no longer than until then; past, 403.
  const long long now = std::time(nullptr);
  const std::string later = target + "&exp=" + std::to_string(now + 100);
  auto r = get(later + "&sig=" + UrlSigning::sign(keyNew, later));
  EXPECT_EQ(r->status, 200);
  const int maxAge = std::stoi(r->get_header_value("Cache-Control").substr(std::string("public, max-age=").size()));
  EXPECT_LE(maxAge, 100);
  EXPECT_GE(maxAge, 95);
  const std::string earlier = target + "&exp=" + std::to_string(now - 5);
  auto expired = get(earlier + "&sig=" + UrlSigning::sign(keyNew, earlier));
  EXPECT_EQ(expired->status, 403);
  EXPECT_NE(expired->body.find("expired"), std::string::npos);
  EXPECT_EQ(get(later + "&sig=" + UrlSigning::sign(keyNew, target))->status, 403);  // exp added after signing
  // POSTs are not signed (without API keys they stay open).
  EXPECT_EQ(s.postJson("/v1/fog", kFog)->status, 200);
  // Rotation: the old key leaves the file; after the reload it no longer signs.
  std::ofstream(c.urlSigningKeyFile) << keyNew << "\n";
  EXPECT_EQ(s.service().reloadAccess(), "");
  EXPECT_EQ(get(target + "&sig=" + UrlSigning::sign(keyOld, target))->status, 403);
  EXPECT_EQ(get(target + "&sig=" + UrlSigning::sign(keyNew, target))->status, 200);
  std::filesystem::remove(c.urlSigningKeyFile);
}

// One raw request (headers as given, NUL and all), its status.
int rawStatus(int port, const std::string& request) {
  httplib::Client probe("127.0.0.1", port);  // waits until the server listens
  (void)probe.Get("/healthz");
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(uint16_t(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) return ::close(fd), -1;
  (void)::send(fd, request.data(), request.size(), 0);
  char buf[64] = {};
  const ssize_t n = ::recv(fd, buf, sizeof buf - 1, 0);
  ::close(fd);
  return n > 12 ? std::atoi(buf + 9) : -1;
}

// The edges of a key and a URL, each one way: a control character in any header is a 400 (a key
// compared up to a NUL let "<secret>\0junk" in); several spaces after Bearer are one (RFC 9110: 1*SP);
// r, exp and sig each once, and r without padding.
TEST(Urls, StrictEdges) {
  Config c = TestServer::quietConfig();
  const std::string secret = "secret-of-the-edges";
  c.apiKeysFile = writeFile(
      "edge-keys",
      json{{"keys", {{{"id", "edge"}, {"sha256", sha256Hex(secret)}, {"perMinute", 600}, {"burst", 100}}}}}.dump());
  TestServer s(c);
  const std::string body = kFog.dump();
  auto post = [&](const std::string& auth) {
    return rawStatus(s.port(), "POST /v1/fog HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nAuthorization: " +
                                   auth + "\r\nContent-Length: " + std::to_string(body.size()) +
                                   "\r\nConnection: close\r\n\r\n" + body);
  };
  EXPECT_EQ(post("Bearer " + secret), 200);
  EXPECT_EQ(post("Bearer    " + secret), 200);
  EXPECT_EQ(post("bearer " + secret), 200);
  EXPECT_EQ(post("Bearer\t" + secret), 401);  // 1*SP, not HTAB
  EXPECT_EQ(post("Bearer " + secret + std::string(1, '\0') + "junk"), 400);
  EXPECT_EQ(post("Bearer " + secret + "\x01"), 400);
  EXPECT_EQ(post("Bearer " + secret + "x"), 403);
  EXPECT_EQ(post("Bearer "), 401);
  std::filesystem::remove(c.apiKeysFile);

  TestServer open;
  const std::string target = url("/v1/fog", kFog), r = target.substr(target.find("r=") + 2);
  auto get = [&](const std::string& t) { return open.client().Get(t.c_str()); };
  EXPECT_EQ(get(target)->status, 200);
  for (const auto& [t, pointer] : {std::pair{target + "&r=" + r, "?r"}, std::pair{target + "&exp=1&exp=2", "?exp"},
                                   std::pair{target + "&sig=a&sig=b", "?sig"}, std::pair{target + "==", "?r"}}) {
    auto a = get(t);
    ASSERT_TRUE(a);
    EXPECT_EQ(a->status, 400) << t;
    EXPECT_EQ(json::parse(a->body)["errors"][0]["pointer"], pointer) << t << a->body;
    EXPECT_EQ(a->get_header_value("Cache-Control"), "no-store");
  }
}

TEST(Urls, ApiKeysAuthenticateAndQuotasChargeTheEstimatedCost) {
  Config c = TestServer::quietConfig();
  c.accessLog = true;
  c.responseCacheMb = 0;  // every request computed and charged its cost
  const std::string secretA = "secret-of-game-a", secretB = "secret-of-tool-b";
  c.apiKeysFile = writeFile("keys", json{{"keys",
                                          {{{"id", "game-a"}, {"sha256", sha256Hex(secretA)}, {"perMinute", 60}, {"burst", 200}},
                                           {{"id", "tool-b"},
                                            {"sha256", sha256Hex(secretB)},
                                            {"perMinute", 6},
                                            {"burst", 3},
                                            {"endpoints", {"/v1/fog"}}}}}}
                                        .dump());
  ::testing::internal::CaptureStderr();
  {
    TestServer s(c);
    auto post = [&](const std::string& path, const json& body, const std::string& secret) {
      httplib::Headers h;
      if (!secret.empty()) h.emplace("Authorization", "Bearer " + secret);
      auto r = s.client().Post(path.c_str(), h, body.dump(), "application/json");
      EXPECT_TRUE(r);
      return r;
    };
    auto none = post("/v1/fog", kFog, "");
    EXPECT_EQ(none->status, 401);
    EXPECT_EQ(none->get_header_value("WWW-Authenticate"), "Bearer realm=\"effectd\"");
    EXPECT_EQ(post("/v1/fog", kFog, "a-secret-nobody-has")->status, 403);
    EXPECT_EQ(post("/v1/lightning", json{{"grid", {{"width", 32}, {"height", 32}}}, {"start", {16, 0}}, {"targets", {{16, 31}}}}, secretB)->status, 403);  // not its endpoint
    // Unsigned GETs need the key as POSTs do, and their answers are the key's own.
    EXPECT_EQ(s.client().Get(url("/v1/fog", kFog).c_str())->status, 401);
    auto keyed = s.client().Get(url("/v1/fog", kFog).c_str(), httplib::Headers{{"Authorization", "Bearer " + secretA}});
    EXPECT_EQ(keyed->status, 200);
    EXPECT_EQ(keyed->get_header_value("Cache-Control"), "private, max-age=3600");

    // A small fog table costs 1 unit; a 1024² bolt many more.
    auto small = post("/v1/fog", kFog, secretA);
    ASSERT_EQ(small->status, 200);
    EXPECT_EQ(small->get_header_value("RateLimit-Policy"), "\"key\";q=60;w=60");
    auto remaining = [](const httplib::Result& r) {
      const std::string v = r->get_header_value("RateLimit");
      return std::stod(v.substr(v.find(";r=") + 3));
    };
    EXPECT_EQ(remaining(small), 198);  // the GET above, then this
    auto bolt = post("/v1/lightning", json{{"grid", {{"width", 1024}, {"height", 1024}}}, {"start", {512, 0}}, {"targets", {{512, 1023}}}, {"seed", 1}}, secretA);
    ASSERT_EQ(bolt->status, 200) << bolt->body;
    const double boltUnits = std::stod(bolt->get_header_value("X-Memory-Reserved")) / double(1 << 20);
    EXPECT_GT(198 - remaining(bolt), 5.0) << "a 1024² bolt costs more than a fog table";
    EXPECT_NEAR(198 - remaining(bolt), std::ceil(boltUnits), 2.0);

    // tool-b: a burst of 3 units, then 429 with when to come back.
    for (int i = 0; i < 3; ++i) EXPECT_EQ(post("/v1/fog", kFog, secretB)->status, 200) << i;
    auto limited = post("/v1/fog", kFog, secretB);
    EXPECT_EQ(limited->status, 429);
    EXPECT_GE(std::stoi(limited->get_header_value("Retry-After")), 1);
    EXPECT_LE(std::stoi(limited->get_header_value("Retry-After")), 10);  // 6 a minute: one unit every 10 s
    EXPECT_FALSE(limited->get_header_value("RateLimit").empty());
    EXPECT_EQ(json::parse(limited->body)["type"], "https://effectd.dev/problems/quota-exceeded");

    const std::string metrics = s.client().Get("/metrics")->body;
    EXPECT_NE(metrics.find("effectd_key_requests_total{key=\"tool-b\",outcome=\"limited\"} 1"), std::string::npos);
    EXPECT_NE(metrics.find("effectd_key_requests_total{key=\"tool-b\",outcome=\"allowed\"} 3"), std::string::npos);
    EXPECT_NE(metrics.find("effectd_access_refused_total{reason=\"unauthenticated\"} 2"), std::string::npos);

    // A new key file, reread without a restart: tool-b's secret is gone.
    std::ofstream(c.apiKeysFile)
        << json{{"keys", {{{"id", "game-a"}, {"sha256", sha256Hex(secretA)}, {"perMinute", 60}, {"burst", 200}}}}}.dump();
    EXPECT_EQ(s.service().reloadAccess(), "");
    EXPECT_EQ(post("/v1/fog", kFog, secretB)->status, 403);
    std::ofstream(c.apiKeysFile) << "{\"keys\": [{\"id\": \"x\"}]}";  // wrong: the old keys stay
    EXPECT_NE(s.service().reloadAccess().find("/keys/0/sha256"), std::string::npos);
    EXPECT_EQ(post("/v1/fog", kFog, secretA)->status, 200);
  }
  const std::string log = ::testing::internal::GetCapturedStderr();
  EXPECT_NE(log.find("\"key\":\"game-a\""), std::string::npos);
  EXPECT_NE(log.find("\"key\":\"tool-b\""), std::string::npos);
  for (const auto& secret : {secretA, secretB}) EXPECT_EQ(log.find(secret), std::string::npos) << "a secret in the log";
  std::filesystem::remove(c.apiKeysFile);
}

TEST(Urls, QuotasFailOpenToLocalBucketsWhenRedisIsUnreachable) {
  Config c = TestServer::quietConfig();
  c.apiKeysFile = writeFile(
      "keys-redis",
      json{{"keys", {{{"id", "k"}, {"sha256", sha256Hex("secret-k-123")}, {"perMinute", 60}, {"burst", 2}}}}}.dump());
  c.quotaRedis = "redis://127.0.0.1:1";  // nothing listens there
  c.responseCacheMb = 0;
  TestServer s(c);
  httplib::Headers h = {{"Authorization", "bearer secret-k-123"}};  // the scheme in any case
  int allowed = 0, limited = 0;
  for (int i = 0; i < 4; ++i) {
    auto r = s.client().Post("/v1/fog", h, kFog.dump(), "application/json");
    ASSERT_TRUE(r);
    (r->status == 200 ? allowed : limited) += 1;
  }
  EXPECT_EQ(allowed, 2);  // this process's own bucket still holds the key to its burst
  EXPECT_EQ(limited, 2);
  // An admitted request is charged twice (its first unit before its body is read, the rest
  // before admission), a refused one once: 2 * 2 + 2.
  EXPECT_NE(s.client().Get("/metrics")->body.find("effectd_quota_charges_total{store=\"local-fallback\"} 6"),
            std::string::npos);
  std::filesystem::remove(c.apiKeysFile);
}

TEST(Urls, KeyFilesThatAreWrongStopTheStart) {
  Config c = TestServer::quietConfig();
  c.apiKeysFile = writeFile("bad-keys", "{\"keys\": [{\"id\": \"a\", \"sha256\": \"12\", \"perMinute\": 1, \"burst\": 1}]}");
  EXPECT_THROW(Service{c}, std::runtime_error);
  c.apiKeysFile.clear();
  c.urlSigningKeyFile = writeFile("short-key", "short\n");
  EXPECT_THROW(Service{c}, std::runtime_error);
}

}  // namespace
}  // namespace effectd::testing
