// Faults over real sockets: clients that vanish mid-request and mid-response, slow clients
// (slowloris), and a service that keeps answering everyone else meanwhile.
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <thread>
#include <vector>

#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

void expectHealthy(const TestServer& s) {
  auto r = s.client().Get("/healthz");
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

const std::string kBigFog = R"({"fog":{"fogType":"HEIGHT","density":0.1},"table":{"size":256,"elevations":256}})";

TEST(Faults, ClientsThatVanishMidRequestOrMidResponse) {
  TestServer s;
  for (int i = 0; i < 20; ++i) {
    // Mid-request: headers promise 1000 bytes, 10 arrive, the client leaves.
    int fd = connectLoopback(s.port());
    ASSERT_GE(fd, 0);
    sendAll(fd,
            "POST /v1/fog HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: "
            "1000\r\n\r\n{\"fog\":{\"");
    ::close(fd);
    // Mid-response: a large answer, of which the client reads a few bytes and leaves.
    fd = connectLoopback(s.port());
    ASSERT_GE(fd, 0);
    sendAll(fd, "POST /v1/fog HTTP/1.1\r\nHost: x\r\nContent-Type: application/json\r\nContent-Length: " +
                    std::to_string(kBigFog.size()) + "\r\n\r\n" + kBigFog);
    char buf[64];
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 5000) > 0) (void)::recv(fd, buf, sizeof buf, 0);
    ::close(fd);
  }
  expectHealthy(s);
  auto r = s.postJson("/v1/fog", kBigFog);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->status, 200);
}

TEST(Faults, SlowClientsDoNotStarveOthers) {
  Config c = TestServer::quietConfig();
  c.readTimeoutS = 1;
  c.threads = 4;
  TestServer s(c);
  // Slowloris: twice as many slow connections as worker threads, one header byte every 300 ms.
  std::vector<int> slow;
  for (int i = 0; i < 8; ++i) {
    int fd = connectLoopback(s.port());
    ASSERT_GE(fd, 0);
    sendAll(fd, "POST /v1/fog HTTP/1.1\r\nHo");
    slow.push_back(fd);
  }
  std::atomic<bool> stop{false};
  std::thread trickle([&] {
    while (!stop) {
      for (int fd : slow) (void)::send(fd, "s", 1, MSG_NOSIGNAL);
      std::this_thread::sleep_for(std::chrono::milliseconds(300));
    }
  });
  // Meanwhile ordinary clients are answered promptly.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  for (int i = 0; i < 5; ++i) {
    const auto start = std::chrono::steady_clock::now();
    httplib::Client client("127.0.0.1", s.port());
    client.set_connection_timeout(5, 0);
    client.set_read_timeout(5, 0);
    auto r = client.Get("/healthz");
    EXPECT_TRUE(r && r->status == 200) << "request " << i << " during the slow-client attack";
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(3)) << "request " << i;
  }
  stop = true;
  trickle.join();
  for (int fd : slow) ::close(fd);
  expectHealthy(s);
}

}  // namespace
}  // namespace effectd::testing
