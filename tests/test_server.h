// A real effectd service on an ephemeral loopback port, for API tests.
#pragma once

#include <httplib.h>

#include <filesystem>
#include <fstream>
#include <iterator>
#include <memory>
#include <string>
#include <thread>

#include <gtest/gtest.h>
#include <nlohmann/json.hpp>

#include "app/endpoints.h"
#include "http/service.h"

namespace effectd::testing {

class TestServer {
 public:
  explicit TestServer(Config config = quietConfig()) : service_(std::make_unique<Service>(config)) {
    addEffectEndpoints(*service_);
    port_ = service_->bind();
    thread_ = std::thread([this] { service_->run(); });
    service_->waitUntilRunning(std::chrono::seconds(5));
  }
  ~TestServer() {
    service_->stop();
    thread_.join();
  }
  static Config quietConfig() {
    Config c;
    c.host = "127.0.0.1";
    c.port = 0;
    c.threads = 4;
    c.accessLog = false;
    return c;
  }
  int port() const { return port_; }
  Service& service() { return *service_; }
  httplib::Client client() const {
    httplib::Client c("127.0.0.1", port_);
    c.set_read_timeout(60, 0);
    return c;
  }
  httplib::Result postJson(const std::string& path, const std::string& body) const {
    return client().Post(path.c_str(), body, "application/json");
  }
  httplib::Result postJson(const std::string& path, const nlohmann::json& body) const {
    return postJson(path, body.dump());
  }

 private:
  std::unique_ptr<Service> service_;
  int port_ = -1;
  std::thread thread_;
};

// One client connection kept alive across requests, each request sent in a single write.
class KeepAlive {
 public:
  explicit KeepAlive(int port);
  ~KeepAlive();
  KeepAlive(const KeepAlive&) = delete;
  KeepAlive& operator=(const KeepAlive&) = delete;
  bool ok() const { return fd_ >= 0; }
  // Sends `bytes` and returns what came back: one whole response (head + Content-Length
  // bytes), or everything until the server closed the connection or `timeoutMs` passed.
  std::string exchange(const std::string& bytes, int timeoutMs = 5000);

 private:
  int fd_;
};
// Sends raw bytes over a fresh TCP connection and returns what the server answered (as
// KeepAlive::exchange).
std::string rawExchange(int port, const std::string& bytes, int timeoutMs = 3000);
// A TCP connection to 127.0.0.1:port, or -1.
int connectLoopback(int port);
// Writes all of `bytes` to a socket (stops quietly when the peer has gone).
void sendAll(int fd, const std::string& bytes);

// A whole file as bytes.
inline std::string slurp(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Parses a problem+json response and checks the RFC 9457 members.
inline nlohmann::json expectProblem(const httplib::Result& r, int status) {
  EXPECT_TRUE(r) << "no response";
  if (!r) return {};
  EXPECT_EQ(r->status, status) << r->body;
  EXPECT_EQ(r->get_header_value("Content-Type"), "application/problem+json");
  auto j = nlohmann::json::parse(r->body, nullptr, false);
  EXPECT_TRUE(j.is_object()) << r->body;
  if (!j.is_object()) return {};
  EXPECT_EQ(j.value("status", 0), status);
  EXPECT_TRUE(j.contains("type") && j.contains("title") && j.contains("detail") && j.contains("requestId")) << r->body;
  EXPECT_EQ(j.value("requestId", ""), r->get_header_value("X-Request-ID"));
  return j;
}

// True when some entry of problem["errors"] has exactly this pointer.
inline bool hasPointer(const nlohmann::json& problem, const std::string& pointer) {
  if (!problem.contains("errors")) return false;
  for (const auto& e : problem["errors"])
    if (e.value("pointer", "") == pointer) return true;
  return false;
}

}  // namespace effectd::testing
