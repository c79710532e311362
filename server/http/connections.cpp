#include "http/connections.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cstring>

#include "contract/problem.h"
#include "http/request_state.h"

namespace effectd {
namespace {

using Clock = std::chrono::steady_clock;

thread_local bool closeAfterAnswer_ = false;  // EdgeServer::closeAfterThisAnswer()
thread_local size_t unreadBody_ = 0;          // EdgeServer::skipUnreadBody()
thread_local bool overCapacityHere_ = false;  // EdgeServer::overCapacity()

// Waits until `sock` is ready for `events` or `deadline` passes; false on timeout or error.
bool waitFor(int sock, short events, Clock::time_point deadline) {
  for (;;) {
    const auto left = std::chrono::duration_cast<std::chrono::microseconds>(deadline - Clock::now()).count();
    if (left <= 0) return false;
    pollfd p{sock, events, 0};
    const int n = ::poll(&p, 1, int(std::min<long long>((left + 999) / 1000, 1 << 30)));  // rounded up
    if (n > 0) return true;
    if (n == 0) return false;
    if (errno != EINTR) return false;
  }
}

// An answer written straight to the socket, outside cpp-httplib: status line, headers, problem.
std::string rawProblem(const ApiError& problem) {
  httplib::Response res;
  writeProblem(res, problem, newRequestId());
  std::string out = "HTTP/1.1 " + std::to_string(res.status) + " " + statusTitle(res.status) + "\r\n";
  for (const auto& [name, value] : res.headers) out += name + ": " + value + "\r\n";
  out += "Content-Length: " + std::to_string(res.body.size()) + "\r\nConnection: close\r\n\r\n" + res.body;
  return out;
}

void sendAll(int sock, const std::string& data, Clock::time_point deadline) {
  for (size_t at = 0; at < data.size();) {
    if (!waitFor(sock, POLLOUT, deadline)) return;
    const ssize_t n = ::send(sock, data.data() + at, data.size() - at, MSG_NOSIGNAL);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) return;
    at += size_t(n);
  }
}

// Closes `sock` after an answer it has not read the request for: the write side first, then
// what the client still sends is read and dropped for a moment, so that closing with unread
// bytes does not reset the connection before the client has read the answer.
void closeAfterAnswer(int sock) {
  ::shutdown(sock, SHUT_WR);
  const auto until = Clock::now() + std::chrono::milliseconds(100);
  char sink[4096];
  while (waitFor(sock, POLLIN, until)) {
    const ssize_t n = ::recv(sock, sink, sizeof sink, 0);
    if (n == 0 || (n < 0 && errno != EINTR)) break;
  }
  ::close(sock);
}

// A connection's stream for cpp-httplib's request parser: reads buffered (the parser reads
// header lines a byte at a time), every read bounded by the request's deadline, every write
// by the write timeout. A read that passes the deadline answers 408 and fails.
class DeadlineStream final : public httplib::Stream {
 public:
  DeadlineStream(int sock, std::chrono::microseconds writeTimeout) : sock_(sock), writeTimeout_(writeTimeout) {}

  void startRequest(Clock::time_point deadline) {
    deadline_ = deadline;
    timedOut_ = false;
  }
  bool timedOut() const { return timedOut_; }
  bool buffered() const { return off_ < size_; }

  bool is_readable() const override { return off_ < size_ || waitReadable(); }
  bool is_writable() const override { return !timedOut_ && waitFor(sock_, POLLOUT, Clock::now() + writeTimeout_); }

  ssize_t read(char* ptr, size_t size) override {
    if (off_ < size_) {
      const size_t n = std::min(size, size_ - off_);
      std::memcpy(ptr, buffer_.data() + off_, n);
      off_ += n;
      return ssize_t(n);
    }
    if (!waitReadable()) return -1;
    for (;;) {
      const bool buffered = size < buffer_.size();
      const ssize_t n = ::recv(sock_, buffered ? buffer_.data() : ptr, buffered ? buffer_.size() : size, 0);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0 || !buffered) return n;
      size_ = size_t(n);
      off_ = std::min(size, size_);
      std::memcpy(ptr, buffer_.data(), off_);
      return ssize_t(off_);
    }
  }

  ssize_t write(const char* ptr, size_t size) override {
    if (!is_writable()) return -1;
    for (;;) {
      const ssize_t n = ::send(sock_, ptr, size, MSG_NOSIGNAL);
      if (n < 0 && errno == EINTR) continue;
      return n;
    }
  }

  void get_remote_ip_and_port(std::string& ip, int& port) const override { address(::getpeername, ip, port); }
  void get_local_ip_and_port(std::string& ip, int& port) const override { address(::getsockname, ip, port); }
  socket_t socket() const override { return sock_; }

 private:
  // Whether more of the request arrives before its deadline; past it, answers 408 (once).
  bool waitReadable() const {
    if (timedOut_) return false;
    if (waitFor(sock_, POLLIN, deadline_)) return true;
    if (Clock::now() >= deadline_) timeOut();
    return false;
  }

  // The request did not arrive in time: 408, and nothing more is read or written.
  void timeOut() const {
    timedOut_ = true;
    sendAll(sock_,
            rawProblem({408,
                        "request-timeout",
                        "Request Timeout",
                        "the request's headers and body did not all arrive within --read-timeout",
                        {},
                        {{"Cache-Control", "no-store"}}}),
            Clock::now() + writeTimeout_);
  }

  template <class Get>
  void address(Get get, std::string& ip, int& port) const {
    sockaddr_storage a{};
    socklen_t length = sizeof a;
    ip.clear();
    port = 0;
    if (get(sock_, reinterpret_cast<sockaddr*>(&a), &length) != 0) return;
    char text[INET6_ADDRSTRLEN] = "";
    if (a.ss_family == AF_INET) {
      const auto* v4 = reinterpret_cast<const sockaddr_in*>(&a);
      ::inet_ntop(AF_INET, &v4->sin_addr, text, sizeof text);
      port = ntohs(v4->sin_port);
    } else if (a.ss_family == AF_INET6) {
      const auto* v6 = reinterpret_cast<const sockaddr_in6*>(&a);
      ::inet_ntop(AF_INET6, &v6->sin6_addr, text, sizeof text);
      port = ntohs(v6->sin6_port);
    }
    ip = text;
  }

  const int sock_;
  const std::chrono::microseconds writeTimeout_;
  Clock::time_point deadline_{};
  mutable bool timedOut_ = false;
  std::array<char, 4096> buffer_{};
  size_t off_ = 0, size_ = 0;
};

}  // namespace

void EdgeServer::closeAfterThisAnswer() { closeAfterAnswer_ = true; }
void EdgeServer::skipUnreadBody(size_t bytes) { unreadBody_ = bytes; }
bool EdgeServer::overCapacity() { return overCapacityHere_; }

ApiError EdgeServer::overCapacityProblem() {
  return {503,
          "overloaded",
          "Service Unavailable",
          "the server holds all the connections it serves at once (--max-connections)",
          {},
          {{"Retry-After", "1"}, {"Cache-Control", "no-store"}, {"Connection", "close"}}};
}

bool EdgeServer::waitForRequest(socket_t sock) const {
  // Polled in short steps, as cpp-httplib's keep-alive wait, so that a stop is seen.
  const auto until = Clock::now() + std::chrono::seconds(keep_alive_timeout_sec_);
  while (svr_sock_ != INVALID_SOCKET) {
    if (waitFor(sock, POLLIN, std::min(until, Clock::now() + std::chrono::milliseconds(50)))) return true;
    if (Clock::now() >= until) return false;
  }
  return false;
}

std::shared_ptr<void> EdgeServer::holdAsStream() {
  std::lock_guard lock(mu_);
  ++streaming_;
  return std::shared_ptr<void>(nullptr, [this](void*) {
    std::lock_guard lock(mu_);
    --streaming_;
  });
}

bool EdgeServer::process_and_close_socket(socket_t sock) {
  const auto writeTimeout = std::chrono::seconds(write_timeout_sec_) + std::chrono::microseconds(write_timeout_usec_);
  bool refuse = false, draining = false, over = false;
  {
    std::lock_guard lock(mu_);
    draining = draining_;
    over = !draining && open_.size() - std::min(streaming_, open_.size()) >= maxConnections_;
    refuse = draining || (over && overCapacityNow_ >= kOverCapacityConnections);
    if (!refuse && !over) open_.insert(sock);
    if (over && !refuse) ++overCapacityNow_;  // not among the open: they stay maxConnections
  }
  if (refuse) {
    ++refused_;
    ApiError problem = overCapacityProblem();
    if (draining) problem.detail = "the server is shutting down";
    problem.headers.erase("Connection");  // rawProblem says it
    sendAll(sock, rawProblem(problem), Clock::now() + writeTimeout);
    closeAfterAnswer(sock);
    return true;
  }
  if (over) {  // one request, read quickly; answered as overCapacity() says, then closed
    ++overCapacity_;
    DeadlineStream stream(sock, writeTimeout);
    stream.startRequest(Clock::now() + std::chrono::milliseconds(kOverCapacityReadMs));
    bool closed = false;
    overCapacityHere_ = true;
    const bool ok = process_request(stream, true, closed, nullptr);
    overCapacityHere_ = false;
    closeAfterAnswer_ = false;
    unreadBody_ = 0;
    tl = RequestState{};
    if (stream.timedOut()) ++timedOut_;
    {
      std::lock_guard lock(mu_);
      --overCapacityNow_;
    }
    closeAfterAnswer(sock);
    return ok;
  }

  DeadlineStream stream(sock, writeTimeout);
  const auto readTimeout = std::chrono::seconds(read_timeout_sec_) + std::chrono::microseconds(read_timeout_usec_);
  bool ok = false;
  // A request already read ahead into the stream's buffer (pipelined) needs no wait.
  for (size_t left = keep_alive_max_count_; left > 0 && (stream.buffered() || waitForRequest(sock)); --left) {
    stream.startRequest(Clock::now() + std::chrono::duration_cast<Clock::duration>(readTimeout));
    bool closed = false;
    closeAfterAnswer_ = false;
    unreadBody_ = 0;
    ok = process_request(stream, left == 1, closed, nullptr);
    tl = RequestState{};  // a request cut short before the logger ran releases what it held
    if (stream.timedOut()) ++timedOut_;
    if (!ok || closed || closeAfterAnswer_ || stream.timedOut() || unreadBody_ > kMaxSkippedBody) break;
    // A refused request's body is still on the way: skipped, within the same deadline.
    char sink[4096];
    while (unreadBody_ > 0) {
      const ssize_t n = stream.read(sink, std::min(unreadBody_, sizeof sink));
      if (n <= 0) break;
      unreadBody_ -= size_t(n);
    }
    if (unreadBody_ > 0) break;
  }
  {
    std::lock_guard lock(mu_);
    open_.erase(sock);
  }
  if (stream.timedOut()) {
    closeAfterAnswer(sock);  // the client is still sending: let it read the 408 first
  } else {
    ::shutdown(sock, SHUT_RDWR);
    ::close(sock);
  }
  return ok;
}

void EdgeServer::drain() {
  std::lock_guard lock(mu_);
  draining_ = true;
  // The read side only: a connection waiting for (more of) a request sees its end at once and
  // closes; one whose answer is being computed still writes it.
  for (socket_t sock : open_) ::shutdown(sock, SHUT_RD);
  drained_ += open_.size();
}

EdgeServer::Counts EdgeServer::counts() const {
  std::lock_guard lock(mu_);
  return {open_.size(), refused_.load(), timedOut_.load(), drained_.load(), overCapacity_.load()};
}

std::string EdgeServer::metricsText() const {
  const Counts c = counts();
  return "# HELP effectd_connections_open Connections being served.\n# TYPE effectd_connections_open gauge\n"
         "effectd_connections_open " + std::to_string(c.open) + "\n" +
         "# HELP effectd_connections_closed_total Connections closed by the server before an answer, by reason: "
         "over --max-connections or draining (503), a request not received within --read-timeout (408), closed "
         "idle or sending at shutdown (drained).\n# TYPE effectd_connections_closed_total counter\n"
         "effectd_connections_closed_total{reason=\"refused\"} " + std::to_string(c.refused) + "\n" +
         "effectd_connections_closed_total{reason=\"request-timeout\"} " + std::to_string(c.timedOut) + "\n" +
         "effectd_connections_closed_total{reason=\"drained\"} " + std::to_string(c.drained) + "\n" +
         "# HELP effectd_connections_over_capacity_total Connections past --max-connections read for one request "
         "(health and readiness answered, the rest refused).\n# TYPE effectd_connections_over_capacity_total counter\n"
         "effectd_connections_over_capacity_total " + std::to_string(c.overCapacity) + "\n";
}

}  // namespace effectd
