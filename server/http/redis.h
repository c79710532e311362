// A Redis connection speaking RESP2: commands as arrays of bulk strings, replies parsed whole
// (strings, integers, arrays, nil, errors). Shared by the quotas (quota.cpp) and the jobs'
// shared store (jobs_redis.cpp).
//
// One command at a time (a mutex); every wait is bounded by the timeout. A failed exchange
// drops the connection; the next command connects again, but not within `retry` of a failure,
// so that an unreachable Redis costs a caller one timeout per `retry`, not one per command.
#pragma once

#include <atomic>
#include <chrono>
#include <cstdint>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace effectd {

struct RedisReply {
  enum class Type { kNil, kString, kInteger, kArray, kError } type = Type::kNil;
  std::string text;  // a string's bytes, or an error's message
  long long integer = 0;
  std::vector<RedisReply> items;
  bool isString() const { return type == Type::kString; }
};

class RedisClient {
 public:
  // `url`: redis://[[user]:password@]host[:port][/...] (the path is ignored; the user and
  // password percent-decoded). With a password every connection starts with AUTH.
  RedisClient(const std::string& url, std::chrono::milliseconds timeout,
              std::chrono::milliseconds retry = std::chrono::seconds(1));
  ~RedisClient();
  RedisClient(const RedisClient&) = delete;
  RedisClient& operator=(const RedisClient&) = delete;

  // The reply (an error reply included: Type::kError), or nullopt when Redis could not be
  // reached, did not answer within the timeout, or answered what is not RESP.
  std::optional<RedisReply> command(const std::vector<std::string>& args);
  // "" when Redis answers PING now, else why not (for /readyz: it waits up to the timeout).
  std::string problem();
  // What went wrong in the last exchange ("unreachable at ...", "refused AUTH at ...: ...",
  // "answers OOM ... at ..." for an error reply; "" when it went well), and where Redis is:
  // states to read without waiting.
  std::string lastProblem() const;
  std::string address() const { return host_ + ":" + port_; }
  // Exchanges that failed since start (Redis away, slow or not speaking RESP): /metrics.
  uint64_t failures() const { return failures_.load(); }

 private:
  bool connect();
  void disconnect();
  bool send(const std::string& bytes);
  bool fill();  // reads more bytes into buffer_
  bool readLine(std::string& line);
  bool readReply(RedisReply& reply, int depth);

  const std::chrono::milliseconds timeout_, retry_;
  std::mutex mutex_;
  bool authenticate();  // AUTH on a new connection, when the URL has a password
  std::string host_, port_, user_, password_, buffer_;
  std::string refused_;              // why Redis refused the last AUTH ("" = it did not)
  mutable std::mutex problemMutex_;  // problem_ is read without waiting for mutex_
  std::string problem_;
  size_t read_ = 0;  // bytes of buffer_ consumed
  int fd_ = -1;
  std::chrono::steady_clock::time_point retryAt_;
  std::atomic<uint64_t> failures_{0};
};

}  // namespace effectd
