// HTTP as clients meet it, measured from the client's side of a real socket: keep-alive
// latency, content negotiation, CORS, the response cache, the memory budget.
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <vector>

#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

// One client connection kept alive across requests, each sent in a single write.
class KeepAlive {
 public:
  explicit KeepAlive(int port) : fd_(connectLoopback(port)) {}
  ~KeepAlive() {
    if (fd_ >= 0) ::close(fd_);
  }
  bool ok() const { return fd_ >= 0; }
  // Sends `request` and reads one whole response (head + Content-Length bytes).
  std::string exchange(const std::string& request) {
    sendAll(fd_, request);
    std::string out;
    char buf[65536];
    pollfd p{fd_, POLLIN, 0};
    while (::poll(&p, 1, 5000) > 0) {
      ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
      if (n <= 0) break;
      out.append(buf, size_t(n));
      auto end = out.find("\r\n\r\n");
      if (end == std::string::npos) continue;
      auto cl = out.find("Content-Length: ");
      if (cl != std::string::npos && cl < end && out.size() >= end + 4 + std::stoul(out.substr(cl + 16))) break;
    }
    return out;
  }

 private:
  int fd_;
};

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

}  // namespace
}  // namespace effectd::testing
