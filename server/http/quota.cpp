#include "http/quota.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <optional>
#include <vector>

#include <arpa/inet.h>
#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

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

// A Redis connection speaking RESP (the protocol's arrays of bulk strings), enough for EVAL.
// One connection, one charge at a time; every wait bounded by kTimeout.
class Quota::Redis {
 public:
  explicit Redis(const std::string& url) {
    std::string rest = url.substr(std::string("redis://").size());
    const size_t slash = rest.find('/');
    if (slash != std::string::npos) rest.resize(slash);
    const size_t colon = rest.rfind(':');
    host_ = colon == std::string::npos ? rest : rest.substr(0, colon);
    port_ = colon == std::string::npos ? "6379" : rest.substr(colon + 1);
  }
  ~Redis() { disconnect(); }

  // The script's {allowed, tokens}, or nullopt when Redis did not answer in time.
  std::optional<std::pair<bool, double>> charge(const ApiKey& key, double units, double need) {
    std::lock_guard lock(mutex_);
    const auto now = std::chrono::steady_clock::now();
    if (fd_ < 0 && now < retryAt_) return std::nullopt;
    char rate[32], burst[32], n[32], least[32];
    std::snprintf(rate, sizeof rate, "%.17g", key.perMinute / 60.0);
    std::snprintf(burst, sizeof burst, "%.17g", key.burst);
    std::snprintf(n, sizeof n, "%.17g", units);
    std::snprintf(least, sizeof least, "%.17g", need);
    const std::vector<std::string> args = {"EVAL", kChargeScript, "1", "effectd:quota:" + key.id, rate, burst, n, least};
    std::string request = "*" + std::to_string(args.size()) + "\r\n";
    for (const auto& a : args) request += "$" + std::to_string(a.size()) + "\r\n" + a + "\r\n";
    if ((fd_ >= 0 || connect()) && send(request)) {
      // *2 :<allowed> $<len> <tokens>
      std::string line;
      if (readLine(line) && line == "*2" && readLine(line) && line.size() > 1 && line[0] == ':') {
        const bool allowed = line.substr(1) == "1";
        if (readLine(line) && line.size() > 1 && line[0] == '$' && readLine(line)) {
          char* end = nullptr;
          const double tokens = std::strtod(line.c_str(), &end);
          if (end && *end == '\0') return std::make_pair(allowed, tokens);
        }
      }
    }
    disconnect();
    retryAt_ = now + std::chrono::seconds(1);
    return std::nullopt;
  }

 private:
  static constexpr int kTimeoutMs = 250;

  bool connect() {
    addrinfo hints{}, *found = nullptr;
    hints.ai_socktype = SOCK_STREAM;
    if (getaddrinfo(host_.c_str(), port_.c_str(), &hints, &found) != 0 || !found) return false;
    fd_ = ::socket(found->ai_family, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
    bool ok = fd_ >= 0;
    if (ok && ::connect(fd_, found->ai_addr, found->ai_addrlen) != 0) {
      pollfd p{fd_, POLLOUT, 0};
      int error = 0;
      socklen_t length = sizeof error;
      ok = errno == EINPROGRESS && ::poll(&p, 1, kTimeoutMs) == 1 &&
           ::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &length) == 0 && error == 0;
    }
    freeaddrinfo(found);
    if (ok) {
      int one = 1;
      ::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    } else {
      disconnect();
    }
    return ok;
  }
  void disconnect() {
    if (fd_ >= 0) ::close(fd_);
    fd_ = -1;
    buffer_.clear();
  }
  bool send(const std::string& bytes) {
    for (size_t done = 0; done < bytes.size();) {
      pollfd p{fd_, POLLOUT, 0};
      if (::poll(&p, 1, kTimeoutMs) != 1) return false;
      const ssize_t n = ::send(fd_, bytes.data() + done, bytes.size() - done, MSG_NOSIGNAL);
      if (n <= 0) return false;
      done += size_t(n);
    }
    return true;
  }
  bool readLine(std::string& line) {
    for (;;) {
      const size_t end = buffer_.find("\r\n");
      if (end != std::string::npos) {
        line = buffer_.substr(0, end);
        buffer_.erase(0, end + 2);
        return line.empty() || line[0] != '-';  // "-ERR ...": an error reply
      }
      if (buffer_.size() > 4096) return false;
      pollfd p{fd_, POLLIN, 0};
      if (::poll(&p, 1, kTimeoutMs) != 1) return false;
      char chunk[512];
      const ssize_t n = ::recv(fd_, chunk, sizeof chunk, 0);
      if (n <= 0) return false;
      buffer_.append(chunk, size_t(n));
    }
  }

  std::mutex mutex_;
  std::string host_, port_, buffer_;
  int fd_ = -1;
  std::chrono::steady_clock::time_point retryAt_;
};

Quota::Quota(const std::string& redisUrl) {
  if (!redisUrl.empty()) redis_ = std::make_unique<Redis>(redisUrl);
}

Quota::~Quota() = default;

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
