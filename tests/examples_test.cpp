// Runs every request in proto/examples against a real server:
//   proto/examples/<endpoint>/*.json  valid bodies for POST /v1/<endpoint> -> 2xx
//   proto/examples/invalid/*.json     {endpoint, body | rawBody, expect: {status, pointer}}
#include <filesystem>
#include <fstream>
#include <sstream>

#include "test_server.h"

namespace effectd::testing {
namespace {

namespace fs = std::filesystem;
using nlohmann::json;

std::string slurp(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  std::stringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

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

TEST(Examples, EveryInvalidExampleIsRefusedNamingTheField) {
  TestServer s;
  auto files = filesIn(fs::path(EFFECTD_PROTO_DIR) / "examples" / "invalid");
  ASSERT_FALSE(files.empty());
  for (const auto& file : files) {
    SCOPED_TRACE(file.string());
    json c = json::parse(slurp(file));
    std::string body = c.contains("rawBody") ? c["rawBody"].get<std::string>() : c["body"].dump();
    std::string type = c.value("contentType", "application/json");
    auto r = s.client().Post(c["endpoint"].get<std::string>().c_str(), body, type.c_str());
    int status = c["expect"]["status"];
    auto p = expectProblem(r, status);
    std::string pointer = c["expect"].value("pointer", "");
    if (!pointer.empty()) {
      EXPECT_TRUE(hasPointer(p, pointer)) << "expected pointer " << pointer << " in " << p.dump();
    }
  }
  auto r = s.client().Get("/healthz");  // still serving
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

}  // namespace
}  // namespace effectd::testing
