#include "http/quota.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <optional>

#include "http/redis.h"

namespace effectd {

namespace {

// What a charge leaves: allowed or not, and when the bucket fills (again) at `perSecond`.
QuotaDecision decide(bool allowed, double tokens, double need, double burst, double perSecond) {
  QuotaDecision d;
  d.allowed = allowed;
  d.remaining = tokens;
  d.retryAfterS = allowed ? 0.0 : std::max(0.0, (need - tokens) / perSecond);
  d.fullInS = std::max(0.0, (burst - tokens) / perSecond);
  return d;
}

// The bucket in Redis: refilled from its last charge by Redis's own clock, charged when it
// holds `need` (never above burst), kept a minute past the time it takes to fill.
constexpr const char* kChargeScript = R"(
local rate, burst, units, need = tonumber(ARGV[1]), tonumber(ARGV[2]), tonumber(ARGV[3]), tonumber(ARGV[4])
local t = redis.call('TIME')
local now = tonumber(t[1]) + tonumber(t[2]) / 1000000
local v = redis.call('HMGET', KEYS[1], 'tokens', 'at')
local tokens, at = tonumber(v[1]) or burst, tonumber(v[2]) or now
tokens = math.min(burst, tokens + math.max(0, now - at) * rate)
local allowed = 0
if tokens >= need then
  tokens = math.min(burst, tokens - units)
  allowed = 1
end
redis.call('HSET', KEYS[1], 'tokens', tostring(tokens), 'at', tostring(now))
redis.call('EXPIRE', KEYS[1], math.ceil((burst + math.max(0, units)) / rate) + 60)
return {allowed, tostring(tokens)}
)";

}  // namespace

double quotaUnits(size_t estimatedBytes) {
  return std::max(1.0, std::ceil(double(estimatedBytes) / double(kQuotaUnitBytes)));
}

// The buckets in Redis (redis.h), one script per charge; every wait bounded by 250 ms.
class Quota::Redis {
 public:
  explicit Redis(const std::string& url) : client_(url, std::chrono::milliseconds(250)) {}

  // The script's {allowed, tokens}, or nullopt when Redis did not answer in time.
  std::optional<std::pair<bool, double>> charge(const ApiKey& key, double units, double need) {
    char rate[32], burst[32], n[32], least[32];
    std::snprintf(rate, sizeof rate, "%.17g", key.perMinute / 60.0);
    std::snprintf(burst, sizeof burst, "%.17g", key.burst);
    std::snprintf(n, sizeof n, "%.17g", units);
    std::snprintf(least, sizeof least, "%.17g", need);
    const auto r = client_.command({"EVAL", kChargeScript, "1", "effectd:quota:" + key.id, rate, burst, n, least});
    // {allowed, tokens}: an integer and a string
    if (!r || r->type != RedisReply::Type::kArray || r->items.size() != 2 ||
        r->items[0].type != RedisReply::Type::kInteger || !r->items[1].isString())
      return std::nullopt;
    char* end = nullptr;
    const double tokens = std::strtod(r->items[1].text.c_str(), &end);
    if (!end || *end != '\0') return std::nullopt;
    return std::make_pair(r->items[0].integer == 1, tokens);
  }

  RedisClient& client() { return client_; }

 private:
  RedisClient client_;
};

Quota::Quota(const std::string& redisUrl) {
  if (!redisUrl.empty()) redis_ = std::make_unique<Redis>(redisUrl);
}

Quota::~Quota() = default;

std::string Quota::storeProblem() const { return redis_ ? redis_->client().problem() : std::string(); }
uint64_t Quota::storeFailures() const { return redis_ ? redis_->client().failures() : 0; }

QuotaDecision Quota::charge(const ApiKey& key, double units, double need) {
  need = std::min(need, key.burst);
  const double perSecond = key.perMinute / 60.0;
  if (redis_) {
    if (auto r = redis_->charge(key, units, need)) {
      std::lock_guard lock(mutex_);
      ++counts_.shared;
      return decide(r->first, r->second, need, key.burst, perSecond);
    }
    std::lock_guard lock(mutex_);
    ++counts_.fallbacks;
  }
  return chargeLocal(key, units, need);
}

QuotaDecision Quota::chargeLocal(const ApiKey& key, double units, double need) {
  const auto now = std::chrono::steady_clock::now();
  std::lock_guard lock(mutex_);
  auto [it, fresh] = buckets_.try_emplace(key.id, Bucket{key.burst, now});
  Bucket& b = it->second;
  const double perSecond = key.perMinute / 60.0;
  if (!fresh)
    b.tokens = std::min(key.burst, b.tokens + std::chrono::duration<double>(now - b.at).count() * perSecond);
  b.at = now;
  const bool allowed = b.tokens >= need;
  if (allowed) b.tokens = std::min(key.burst, b.tokens - units);
  return decide(allowed, b.tokens, need, key.burst, perSecond);
}

Quota::Counts Quota::counts() const {
  std::lock_guard lock(mutex_);
  return counts_;
}

}  // namespace effectd
