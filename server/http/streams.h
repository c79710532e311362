// Who holds the long answers: the event streams (GET /v1/jobs/{id}/events). A stream holds its
// connection, and the connection's thread, for as long as its job runs, so streams are shared
// out (docs/serving.md, "Slow and excess clients"):
//   - a client's own: an API key's `maxStreams` (absent: --key-max-streams), or without keys the
//     client address's --max-streams-per-address; past it that client gets 429 with Retry-After,
//     and no one else notices;
//   - all of them together: --max-streams; past it, 503. A stream's connection and thread are
//     not among --max-connections (EdgeServer::holdAsStream): the pool has --max-streams threads
//     more, so streams never hold the connections and threads that requests need.
#pragma once

#include <cstdint>
#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "contract/problem.h"

namespace effectd {

class Streams {
 public:
  explicit Streams(int total) : total_(total) {}
  int total() const { return total_; }

  // One more stream for `client` ("key <id>" or "address <ip>"), of at most `most` at once
  // (0: no share of its own), named in a refusal by `whose` ("the key 'a' (its maxStreams)").
  // The place is held until `place` is dropped; or the problem that refuses it.
  std::optional<ApiError> enter(const std::string& client, int most, const std::string& whose,
                                std::shared_ptr<void>& place);

  struct Counts {
    size_t held = 0;
    uint64_t refusedClient = 0, refusedTotal = 0;
  };
  Counts counts() const;
  // The Prometheus text of counts().
  std::string metricsText() const;

 private:
  const int total_;
  mutable std::mutex mu_;
  std::map<std::string, int> held_;  // by client, only while it holds some
  size_t all_ = 0;
  uint64_t refusedClient_ = 0, refusedTotal_ = 0;
  std::map<std::string, uint64_t> refusedByKey_;  // by key id (ids are few; addresses are not counted so)
};

}  // namespace effectd
