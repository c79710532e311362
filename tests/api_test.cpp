// Server core over real HTTP: health, readiness, metrics, contract, every error status,
// request ids, limits.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include "contract/resources.h"
#include "test_server.h"

namespace effectd::testing {

int connectLoopback(int port) {
  int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(static_cast<uint16_t>(port));
  addr.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  if (::connect(fd, reinterpret_cast<sockaddr*>(&addr), sizeof addr) != 0) {
    ::close(fd);
    return -1;
  }
  return fd;
}

void sendAll(int fd, const std::string& bytes) {
  for (size_t sent = 0; sent < bytes.size();) {
    ssize_t n = ::send(fd, bytes.data() + sent, bytes.size() - sent, MSG_NOSIGNAL);
    if (n <= 0) return;
    sent += size_t(n);
  }
}

KeepAlive::KeepAlive(int port) : fd_(connectLoopback(port)) {}

KeepAlive::~KeepAlive() {
  if (fd_ >= 0) ::close(fd_);
}

std::string KeepAlive::exchange(const std::string& bytes, int timeoutMs) {
  sendAll(fd_, bytes);
  std::string out;
  char buf[65536];
  pollfd p{fd_, POLLIN, 0};
  while (::poll(&p, 1, timeoutMs) > 0) {
    ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n <= 0) break;
    out.append(buf, size_t(n));
    // Stop once the announced body is complete (keep-alive connections stay open).
    auto end = out.find("\r\n\r\n");
    if (end == std::string::npos) continue;
    auto cl = out.find("Content-Length: ");
    if (cl != std::string::npos && cl < end && out.size() >= end + 4 + std::stoul(out.substr(cl + 16))) break;
  }
  return out;
}

std::string rawExchange(int port, const std::string& bytes, int timeoutMs) {
  KeepAlive c(port);
  return c.ok() ? c.exchange(bytes, timeoutMs) : std::string();
}

namespace {

using nlohmann::json;

TEST(Api, HealthzAndReadyz) {
  TestServer s;
  auto r = s.client().Get("/healthz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["status"], "ok");
  r = s.client().Get("/readyz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["status"], "ready");
}

TEST(Api, ReadyzReportsAComponentThatIsDown) {
  TestServer s;
  s.service().addReadinessCheck("renderer", [] { return std::string("starting"); });
  auto r = s.client().Get("/readyz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 503);
  EXPECT_EQ(json::parse(r->body)["components"]["renderer"], "starting");
}

TEST(Api, ServesTheContract) {
  TestServer s;
  auto r = s.client().Get("/v1/openapi.yaml");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(r->body, std::string(resources().at("openapi.yaml")));
  EXPECT_NE(r->body.find("openapi: 3.1.0"), std::string::npos);
  r = s.client().Get("/v1/schemas/fog.json");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
  EXPECT_EQ(json::parse(r->body)["title"], "POST /v1/fog request");
  expectProblem(s.client().Get("/v1/schemas/nope.json"), 404);
}

TEST(Api, MetricsCountRequestsByRouteAndStatus) {
  TestServer s;
  s.client().Get("/healthz");
  s.client().Get("/healthz");
  s.client().Get("/no/such/thing");
  // A request is counted after its response is written (the access-log hook), so the client
  // can be faster than the count: poll briefly.
  const std::string healthz = "effectd_http_requests_total{route=\"/healthz\",method=\"GET\",status=\"200\"} 2";
  auto r = s.client().Get("/metrics");
  for (int i = 0; i < 100; ++i) {
    if (i > 0) r = s.client().Get("/metrics");
    ASSERT_TRUE(r);
    if (r->body.find(healthz) != std::string::npos && r->body.find("status=\"404\"} 1") != std::string::npos &&
        r->body.find("effectd_http_requests_in_flight 1") != std::string::npos)
      break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  EXPECT_EQ(r->status, 200);
  EXPECT_NE(r->get_header_value("Content-Type").find("text/plain"), std::string::npos);
  const std::string& m = r->body;
  EXPECT_NE(m.find("effectd_http_requests_total{route=\"/healthz\",method=\"GET\",status=\"200\"} 2"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("effectd_http_requests_total{route=\"unmatched\",method=\"GET\",status=\"404\"} 1"),
            std::string::npos)
      << m;
  EXPECT_NE(m.find("effectd_http_request_duration_seconds_bucket{route=\"/healthz\",le=\"+Inf\"} 2"), std::string::npos)
      << m;
  EXPECT_NE(m.find("effectd_http_requests_in_flight 1"), std::string::npos) << m;  // this request
}

TEST(Api, NotFoundIsAProblem) {
  TestServer s;
  auto p = expectProblem(s.client().Get("/v2/nothing"), 404);
  EXPECT_NE(p.value("detail", "").find("/v2/nothing"), std::string::npos);
}

TEST(Api, WrongMethodIs405WithAllow) {
  TestServer s;
  auto r = s.client().Put("/v1/fog", "{}", "application/json");
  expectProblem(r, 405);
  EXPECT_EQ(r->get_header_value("Allow"), "POST, GET, HEAD");
  r = s.client().Post("/healthz", "{}", "application/json");
  expectProblem(r, 405);
  EXPECT_EQ(r->get_header_value("Allow"), "GET, HEAD");
  r = s.client().Delete("/v1/fog");
  expectProblem(r, 405);
}

TEST(Api, MalformedJsonIs400) {
  TestServer s;
  for (std::string body : {"{", "{\"fog\": }", "[1, 2", "{\"fog\": NaN}", "{\"fog\": Infinity}", "\xff\xfe", ""}) {
    auto p = expectProblem(s.postJson("/v1/fog", body), 400);
    EXPECT_EQ(p.value("type", ""), "https://effectd.dev/problems/invalid-json") << body;
  }
  // The pointer names the value being read where the text broke.
  const std::pair<std::string, std::string> where[] = {{R"({"fog": {"fogType": "GL_EXP", "density": NaN}})", "/fog/density"},
                                                       {R"({"samples": {"points": [[0, 0, 0], [1, 2, -Infinity]]}})", "/samples/points/1/2"},
                                                       {R"({"a~b/c": tru})", "/a~0b~1c"},
                                                       {"{\"fog\": {", "/fog"},
                                                       {"[1, 2", ""}};
  for (const auto& [body, pointer] : where) {
    auto p = expectProblem(s.postJson("/v1/fog", body), 400);
    ASSERT_EQ(p["errors"].size(), 1u) << body;
    EXPECT_EQ(p["errors"][0]["pointer"], pointer) << body;
  }
}

TEST(Api, DeepNestingIsRefusedQuickly) {
  TestServer s;
  std::string deep(100000, '[');
  deep += std::string(100000, ']');
  auto p = expectProblem(s.postJson("/v1/fog", deep), 400);
  EXPECT_NE(p.value("detail", "").find("nested deeper"), std::string::npos);
}

TEST(Api, WrongContentTypeIs415) {
  TestServer s;
  auto r = s.client().Post("/v1/fog", "{}", "text/plain");
  expectProblem(r, 415);
  EXPECT_EQ(r->get_header_value("Accept-Post"), "application/json");
}

TEST(Api, FieldErrorsNameTheField) {
  TestServer s;
  auto p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"fogType", "LINEAR"}}}, {"colour", 1}}), 400);
  EXPECT_TRUE(hasPointer(p, "/colour")) << p;
  p = expectProblem(s.postJson("/v1/fog", json::object()), 400);
  EXPECT_TRUE(hasPointer(p, "/fog")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"visibilityRange", -1}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/visibilityRange")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"color", {1, 2, 0}}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/color/1")) << p;
  p = expectProblem(s.postJson("/v1/fog", json{{"fog", {{"fogType", "FOGGY"}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/fogType")) << p;
  p = expectProblem(s.postJson("/v1/fog", std::string("{\"fog\":{\"density\":1e308}}")), 400);
  EXPECT_TRUE(hasPointer(p, "/fog/density")) << p;
  p = expectProblem(s.postJson("/v1/fog", std::string("{\"fog\":{\"density\":1e999}}")), 400);  // overflow
}

TEST(Api, UnservableRequestIs422) {
  TestServer s;
  // d_c = 0: the fog never completes, so the default table range does not exist.
  auto p = expectProblem(
      s.postJson("/v1/fog", json{{"fog", {{"fogType", "DISTANCE_EXP2"}, {"distanceCoefficient", 0}}}}), 422);
  EXPECT_TRUE(hasPointer(p, "/table/range")) << p;
}

TEST(Api, BodyOverTheLimitIs413) {
  Config c = TestServer::quietConfig();
  c.limits.maxBodyBytes = 4096;
  TestServer s(c);
  std::string big = "{\"fog\":{},\"pad\":\"" + std::string(5000, 'x') + "\"}";
  auto p = expectProblem(s.postJson("/v1/fog", big), 413);
  EXPECT_NE(p.value("detail", "").find("4096"), std::string::npos);
}

TEST(Api, ChunkedOrLengthlessBodiesAre411) {
  TestServer s;
  std::string chunked =
      "POST /v1/fog HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nTransfer-Encoding: chunked\r\n\r\n"
      "2\r\n{}\r\n0\r\n\r\n";
  std::string out = rawExchange(s.port(), chunked);
  EXPECT_EQ(out.rfind("HTTP/1.1 411", 0), 0u) << out;
  EXPECT_NE(out.find("application/problem+json"), std::string::npos);
  std::string lengthless =
      "POST /v1/fog HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nConnection: close\r\n\r\n";
  out = rawExchange(s.port(), lengthless);
  EXPECT_EQ(out.rfind("HTTP/1.1 411", 0), 0u) << out;
}

TEST(Api, GarbageRequestLineIs400) {
  TestServer s;
  std::string out = rawExchange(s.port(), "THIS IS NOT HTTP\r\n\r\n");
  EXPECT_EQ(out.rfind("HTTP/1.1 400", 0), 0u) << out;
  EXPECT_NE(out.find("application/problem+json"), std::string::npos) << out;
  EXPECT_NE(out.find("X-Request-ID: "), std::string::npos) << out;
}

TEST(Api, RequestIdIsEchoedWhenSaneAndGeneratedOtherwise) {
  TestServer s;
  auto c = s.client();
  auto r = c.Get("/healthz", {{"X-Request-ID", "abc.DEF_123-x"}});
  ASSERT_TRUE(r);
  EXPECT_EQ(r->get_header_value("X-Request-ID"), "abc.DEF_123-x");
  for (std::string bad :
       {std::string(129, 'a'), std::string("has space"), std::string("semi;colon"), std::string("")}) {
    r = c.Get("/healthz", {{"X-Request-ID", bad}});
    ASSERT_TRUE(r);
    std::string id = r->get_header_value("X-Request-ID");
    EXPECT_NE(id, bad);
    EXPECT_EQ(id.size(), 16u) << id;
  }
  r = c.Get("/healthz");
  ASSERT_TRUE(r);
  auto r2 = c.Get("/healthz");
  ASSERT_TRUE(r2);
  EXPECT_NE(r->get_header_value("X-Request-ID"), r2->get_header_value("X-Request-ID"));
  auto p = expectProblem(c.Get("/missing", {{"X-Request-ID", "trace-1"}}), 404);
  EXPECT_EQ(p["requestId"], "trace-1");
}

TEST(Api, ExceptionsBecome500WithoutInternals) {
  TestServer s;
  // An endpoint whose run step throws, registered the way real ones are.
  Config c = TestServer::quietConfig();
  Service svc(c);
  svc.addJsonEndpoint("/v1/fog", "fog.json", [](const json&, const RequestContext&) {
    return PreparedRequest{Cost{}, []() -> JsonReply { throw std::runtime_error("secret internal detail /etc/passwd"); }};
  });
  int port = svc.bind();
  std::thread t([&] { svc.run(); });
  svc.waitUntilRunning(std::chrono::seconds(5));
  httplib::Client client("127.0.0.1", port);
  auto r = client.Post("/v1/fog", "{\"fog\":{}}", "application/json");
  auto p = expectProblem(r, 500);
  EXPECT_EQ(r->body.find("secret"), std::string::npos);
  EXPECT_FALSE(r->has_header("EXCEPTION_WHAT"));
  svc.stop();
  t.join();
}

TEST(Api, HeadOnGetRoutes) {
  TestServer s;
  auto r = s.client().Head("/healthz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

}  // namespace
}  // namespace effectd::testing

namespace effectd::testing {
namespace {

TEST(Api, StrongEtagsAndNotModified) {
  TestServer s;
  const std::string body = R"({"fog": {"fogType": "GL_EXP", "density": 0.1}, "table": {"size": 8}})";
  auto a = s.postJson("/v1/fog", body);
  ASSERT_TRUE(a);
  const std::string tag = a->get_header_value("ETag");
  ASSERT_EQ(tag.size(), 34u) << "a quoted strong validator";
  EXPECT_EQ(tag.front(), '"');
  // The canonical request decides: key order and spacing do not.
  auto b = s.postJson("/v1/fog", std::string(R"({"table":{"size":8},"fog":{"density":0.1,"fogType":"GL_EXP"}})"));
  EXPECT_EQ(b->get_header_value("ETag"), tag);
  EXPECT_NE(
      s.postJson("/v1/fog", std::string(R"({"fog":{"fogType":"GL_EXP","density":0.2}})"))->get_header_value("ETag"),
      tag);
  // If-None-Match: 304 without a body; other tags, weak forms and lists behave per RFC 9110.
  httplib::Headers h = {{"If-None-Match", tag}};
  auto c = s.client().Post("/v1/fog", h, body, "application/json");
  ASSERT_TRUE(c);
  EXPECT_EQ(c->status, 304);
  EXPECT_TRUE(c->body.empty());
  EXPECT_EQ(c->get_header_value("ETag"), tag);
  h = {{"If-None-Match", "\"other\", W/" + tag}};
  EXPECT_EQ(s.client().Post("/v1/fog", h, body, "application/json")->status, 304);
  h = {{"If-None-Match", "\"other\""}};
  EXPECT_EQ(s.client().Post("/v1/fog", h, body, "application/json")->status, 200);
  // Timings in the body make it vary: no ETag. Problems have none either.
  auto d = s.postJson("/v1/fog", std::string(R"({"fog":{"fogType":"GL_EXP"},"include":["table","stats"]})"));
  EXPECT_FALSE(d->has_header("ETag"));
  auto e = s.postJson("/v1/fog", std::string(R"({"fog":{"fogType":"GL_EXP","density":-1}})"));
  EXPECT_EQ(e->status, 400);
  EXPECT_FALSE(e->has_header("ETag"));
}

}  // namespace
}  // namespace effectd::testing
