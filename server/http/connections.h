// How a listener serves its connections, in effectd's code rather than cpp-httplib's loop
// (docs/serving.md, "Slow and excess clients"). cpp-httplib 0.11.4 times each read alone, so a
// client that sends one header byte every few seconds holds its connection (and a thread) for
// as long as it likes, and a stop waits for it; past the pool's size new connections wait in
// silence. This server keeps cpp-httplib's request parsing and routing (process_request) and
// owns the rest:
//   - a request's headers and body must all arrive within the read timeout, counted from its
//     first byte: otherwise a 408 problem, and the connection is closed;
//   - past `maxConnections` open connections a new one gets a 503 problem at once and is closed;
//   - drain() (SIGTERM) closes every connection that is idle or still sending its request; a
//     request whose answer is being computed finishes and is answered, then its connection closes.
#pragma once

#include <httplib.h>

#include <atomic>
#include <cstdint>
#include <mutex>
#include <set>

namespace effectd {

class EdgeServer : public httplib::Server {
 public:
  explicit EdgeServer(int maxConnections) : maxConnections_(size_t(maxConnections)) {}

  void drain();
  // Called while answering a request (on its thread): the connection closes after this answer,
  // as its Connection: close header says, whatever the request asked (its unread body must not
  // be taken for the next request).
  static void closeAfterThisAnswer();
  // Called while answering a request refused before its body was read: the `bytes` of body
  // that follow its headers are skipped before the next request on the connection (a body
  // over kMaxSkippedBody closes the connection instead).
  static void skipUnreadBody(size_t bytes);
  static constexpr size_t kMaxSkippedBody = 64 << 10;

  struct Counts {
    size_t open = 0;
    uint64_t refused = 0;   // over maxConnections, or draining: 503 at once
    uint64_t timedOut = 0;  // a request not received within the read timeout: 408
    uint64_t drained = 0;   // closed by drain() while idle or sending
  };
  Counts counts() const;
  // The Prometheus text of counts().
  std::string metricsText() const;

 private:
  // cpp-httplib's per-connection entry point (private virtual there; overriding it is allowed).
  bool process_and_close_socket(socket_t sock) override;
  bool waitForRequest(socket_t sock) const;

  const size_t maxConnections_;
  mutable std::mutex mu_;
  std::set<socket_t> open_;
  bool draining_ = false;
  std::atomic<uint64_t> refused_{0}, timedOut_{0}, drained_{0};
};

// Threads a listener needs beyond one per connection: the ones that answer 503 past the limit.
constexpr size_t kRefusalThreads = 16;

}  // namespace effectd
