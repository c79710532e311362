// How a listener serves its connections, in effectd's code rather than cpp-httplib's loop
// (docs/serving.md, "Slow and excess clients"). cpp-httplib 0.11.4 times each read alone, so a
// client that sends one header byte every few seconds holds its connection (and a thread) for
// as long as it likes, and a stop waits for it; past the pool's size new connections wait in
// silence. This server keeps cpp-httplib's request parsing and routing (process_request) and
// owns the rest:
//   - a request's headers and body must all arrive within the read timeout, counted from its
//     first byte: otherwise a 408 problem, and the connection is closed;
//   - past `maxConnections` open connections (a stream's not among them: holdAsStream), up to kOverCapacityConnections more at once are read for
//     one request each within kOverCapacityReadMs and closed after its answer: health and
//     readiness are answered, a client over its own share hears 429 (an event stream: streams.h),
//     anything else 503 (overCapacity()); past those, a new connection gets a 503 at once;
//   - drain() (SIGTERM) closes every connection that is idle or still sending its request; a
//     request whose answer is being computed finishes and is answered, then its connection closes.
#pragma once

#include <httplib.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <set>

#include "contract/problem.h"

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
  // Whether this thread's request came on a connection past maxConnections: only health,
  // readiness and a client's own refusal are answered there, the rest get overCapacityProblem().
  static bool overCapacity();
  static ApiError overCapacityProblem();
  // Called while answering a request that becomes a long answer (an event stream, streams.h):
  // until the token is dropped, its connection does not count against maxConnections, so the
  // connections and threads requests need stay free. The streams' own bound (--max-streams) is
  // the caller's; the pool has a thread for each beyond maxConnections.
  std::shared_ptr<void> holdAsStream();
  static constexpr int kOverCapacityReadMs = 1000;
  static constexpr size_t kMaxSkippedBody = 64 << 10;

  struct Counts {
    size_t open = 0;
    uint64_t refused = 0;   // over maxConnections, or draining: 503 at once
    uint64_t overCapacity = 0;  // past maxConnections, read for one request (health, a refusal)
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
  size_t overCapacityNow_ = 0;  // connections being read past maxConnections (under mu_)
  size_t streaming_ = 0;        // of open_, those holding a stream (holdAsStream; under mu_)
  std::atomic<uint64_t> refused_{0}, timedOut_{0}, drained_{0}, overCapacity_{0};
};

// Connections past maxConnections read for one request at once (health, a client's refusal).
constexpr size_t kOverCapacityConnections = 16;
// Threads a listener needs beyond one per connection and one per stream: those, and the ones
// that answer 503 at once past them.
constexpr size_t kRefusalThreads = kOverCapacityConnections + 16;

}  // namespace effectd
