// Quotas of API keys: one token bucket per key, `burst` units deep, refilled at `perMinute`
// units a minute. A request is charged its admission estimate in units (kQuotaUnitBytes each,
// at least one), so a 4096^2 bolt costs more than a small fog table. A request is let in when
// the bucket holds min(its units, burst): a request larger than the burst passes from a full
// bucket and leaves it in debt, which the refill pays back before the next one. How a request's
// units are taken in steps (one before its body is read, the rest before admission, a refund
// when admission refuses it, and invalid bodies by their size) is access.h's.
//
// The buckets live in this process, or with --quota-redis in Redis, shared by every replica
// (one Lua script per charge, atomic there). Redis unreachable: the charge falls back to this
// process's own bucket (fail open to per-replica quotas: a quota store outage must not stop a
// game's effects, and each replica still holds every key to its quota), and Redis is tried
// again a second later.
#pragma once

#include <chrono>
#include <map>
#include <memory>
#include <mutex>
#include <string>

#include "http/api_keys.h"

namespace effectd {

constexpr size_t kQuotaUnitBytes = 1u << 20;  // one unit per MiB of estimated peak memory
double quotaUnits(size_t estimatedBytes);

struct QuotaDecision {
  bool allowed = false;
  double remaining = 0;    // units left in the bucket after this charge (negative: in debt)
  double retryAfterS = 0;  // not allowed: when the bucket will hold enough
  double fullInS = 0;      // when the bucket will be full again
};

class Quota {
 public:
  // `redisUrl` "" = buckets in this process only.
  explicit Quota(const std::string& redisUrl);
  ~Quota();
  // Takes `units` (negative: gives them back, up to burst) when the bucket holds `need`
  // (capped at burst; kAlways: whatever it holds, into debt if need be).
  QuotaDecision charge(const ApiKey& key, double units, double need);
  static constexpr double kAlways = -1e300;
  // Counters for /metrics: charges Redis answered, and charges it failed (served locally).
  struct Counts {
    unsigned long long shared = 0, fallbacks = 0;
  };
  Counts counts() const;
  bool shared() const { return redis_ != nullptr; }
  // The shared store's state for /readyz ("" = answering, or not shared), and its failed
  // exchanges for /metrics.
  std::string storeProblem() const;
  uint64_t storeFailures() const;

 private:
  struct Bucket {
    double tokens = 0;  // units; negative: in debt
    std::chrono::steady_clock::time_point at;
  };
  QuotaDecision chargeLocal(const ApiKey& key, double units, double need);
  class Redis;
  std::unique_ptr<Redis> redis_;
  mutable std::mutex mutex_;
  std::map<std::string, Bucket> buckets_;
  Counts counts_;
};

}  // namespace effectd
