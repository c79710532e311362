// Runs every request in proto/examples against a real server:
//   proto/examples/<endpoint>/*.json  valid bodies for POST /v1/<endpoint> -> 2xx
//   proto/examples/invalid/*.json     {endpoint, body | rawBody, expect: {status, pointer}}
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>

#include <malloc.h>
#include <unistd.h>

#include "contract/codec.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::vector<fs::path> filesIn(const fs::path& dir) {
  std::vector<fs::path> out;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ".json") out.push_back(e.path());
  std::sort(out.begin(), out.end());
  return out;
}

TEST(Examples, EveryValidExampleIsServed) {
  TestServer s;
  size_t count = 0;
  for (const auto& dir : fs::directory_iterator(fs::path(EFFECTD_PROTO_DIR) / "examples")) {
    if (!dir.is_directory() || dir.path().filename() == "invalid") continue;
    std::string endpoint = "/v1/" + dir.path().filename().string();
    for (const auto& file : filesIn(dir.path())) {
      SCOPED_TRACE(file.string());
      std::string body = slurp(file);
      auto r = s.postJson(endpoint, body);
      ASSERT_TRUE(r);
      EXPECT_EQ(r->status, 200) << r->body.substr(0, 2000);
      EXPECT_FALSE(r->get_header_value("X-Effect-Method").empty());
      if (json::parse(body).value("include", json::array()).dump().find("\"stats\"") == std::string::npos) {
        auto again = s.postJson(endpoint, body);
        ASSERT_TRUE(again);
        EXPECT_EQ(r->body, again->body) << "same request, different bytes";
      }
      ++count;
    }
  }
  EXPECT_GE(count, 5u);
}

// The request bytes of an invalid case: body (JSON), rawBody (text), rawBodyBase64 (any
// bytes, e.g. invalid UTF-8 or a broken GLB) or generate (prefix + repeat * count + suffix,
// for 10 MB strings and 10^5-deep nesting without 10 MB files).
std::string bodyOf(const json& c) {
  if (c.contains("rawBody")) return c["rawBody"].get<std::string>();
  if (c.contains("rawBodyBase64")) return *base64Decode(c["rawBodyBase64"].get<std::string>());
  if (c.contains("generate")) {
    const json& g = c["generate"];
    std::string out = g["prefix"].get<std::string>();
    const std::string unit = g["repeat"].get<std::string>();
    for (size_t i = 0, n = g["count"].get<size_t>(); i < n; ++i) out += unit;
    return out + g["suffix"].get<std::string>();
  }
  return c["body"].dump();
}

// Resident set size of this process (the server runs in it), in bytes.
size_t residentBytes() {
  std::ifstream statm("/proc/self/statm");
  size_t pages = 0, resident = 0;
  statm >> pages >> resident;
  return resident * size_t(sysconf(_SC_PAGESIZE));
}

TEST(Examples, EveryInvalidExampleIsRefusedNamingTheField) {
  TestServer s;
  auto files = filesIn(fs::path(EFFECTD_PROTO_DIR) / "examples" / "invalid");
  ASSERT_GE(files.size(), 150u);
  std::map<std::string, int> perEndpoint;
  // Three passes: after a warm-up pass, a further pass must not grow the process (no leak, no
  // cache growing per request). Large blocks always go straight to mmap and back, so that
  // glibc's sliding mmap threshold does not show 10 MB bodies as heap growth. (Leaks proper
  // are LeakSanitizer's job in the sanitizer suite.)
  mallopt(M_MMAP_THRESHOLD, 1 << 20);
  size_t afterSecond = 0;
  for (int pass = 0; pass < 3; ++pass) {
    for (const auto& file : files) {
      SCOPED_TRACE(file.string());
      json c = json::parse(slurp(file));
      std::string body = bodyOf(c);
      std::string type = c.value("contentType", "application/json");
      auto r = s.client().Post(c["endpoint"].get<std::string>().c_str(), body, type.c_str());
      int status = c["expect"]["status"];
      auto p = expectProblem(r, status);
      std::string pointer = c["expect"].value("pointer", "");
      if (!pointer.empty()) {
        EXPECT_TRUE(hasPointer(p, pointer)) << "expected pointer " << pointer << " in " << p.dump().substr(0, 500);
      }
      if (pass == 0) ++perEndpoint[c["endpoint"].get<std::string>()];
    }
    malloc_trim(0);
    if (pass == 1) afterSecond = residentBytes();
  }
  const size_t afterThird = residentBytes();
  EXPECT_LT(double(afterThird), double(afterSecond) * 1.10 + 8e6) << afterSecond << " -> " << afterThird << " bytes";
  std::printf("RSS after pass 2: %zu bytes, after pass 3: %zu bytes\n", afterSecond, afterThird);
  for (const char* ep : {"/v1/fog", "/v1/lightning", "/v1/tangents", "/v1/bubble", "/v1/render", "/v1/scene"})
    EXPECT_GE(perEndpoint[ep], 10) << ep;
  auto r = s.client().Get("/healthz");  // still serving
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

}  // namespace
}  // namespace effectd::testing
