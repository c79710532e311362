#include "http/access.h"

#include <httplib.h>

#include <cctype>
#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace effectd {

namespace {

ApiError forbidden(const std::string& detail) { return {403, "forbidden", "Forbidden", detail, {}, {}}; }

std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.17g", v);
  return buf;
}

}  // namespace

Access::Access(const Config& config)
    : config_(config),
      signingOn_(!config.urlSigningKeyFile.empty()),
      keysOn_(!config.apiKeysFile.empty()),
      quota_(keysOn_ ? config.quotaRedis : std::string()) {
  if (signingOn_) {
    std::vector<std::string> keys;
    if (auto e = UrlSigning::read(config.urlSigningKeyFile, keys); !e.empty()) throw std::runtime_error(e);
    signing_.setKeys(std::move(keys));
  }
  if (keysOn_) {
    std::vector<ApiKey> keys;
    if (auto e = ApiKeys::read(config.apiKeysFile, keys); !e.empty()) throw std::runtime_error(e);
    keys_.set(std::move(keys));
  }
}

void Access::refused(const std::string& reason) {
  std::lock_guard lock(mutex_);
  ++refusals_[reason];
}

std::optional<ApiError> Access::check(const httplib::Request& req, const std::string& route, long long now,
                                      std::optional<ApiKey>& key, bool jobsRoute) {
  key.reset();
  const bool get = (req.method == "GET" || req.method == "HEAD") && !jobsRoute;
  if (get && signingOn_ && signing_.carriesSignature(req.target)) {
    const std::string why = signing_.verify(req.target, now);
    if (why.empty()) return std::nullopt;  // the URL's owner made it: no key needed
    refused(why.rfind("the URL expired", 0) == 0 ? "expired" : "bad-signature");
    return forbidden(why);
  }
  if (keysOn_) {
    const std::string auth = req.get_header_value("Authorization");
    auto lower = [](std::string t) {
      for (char& c : t) c = char(std::tolower(static_cast<unsigned char>(c)));
      return t;
    };
    // The scheme is case-insensitive, and one or more spaces may follow it (RFC 9110 §11.4).
    const size_t token = auth.find_first_not_of(' ', 6);
    if (lower(auth.substr(0, 7)) != "bearer " || token == std::string::npos) {
      refused("unauthenticated");
      return ApiError{401,
                      "unauthenticated",
                      "Unauthorized",
                      std::string("an API key is required: Authorization: Bearer <secret>") +
                          (signingOn_ && get ? ", or a signed URL" : ""),
                      {},
                      {{"WWW-Authenticate", "Bearer realm=\"effectd\""}}};
    }
    key = keys_.find(auth.substr(token));
    if (!key) {
      refused("unknown-key");
      return forbidden("the API key is not known here");
    }
    if (!jobsRoute && !key->allows(route)) {
      refused("endpoint-not-allowed");
      const std::string id = key->id;
      key.reset();
      return forbidden("the API key '" + id + "' is not allowed on " + route);
    }
    return std::nullopt;
  }
  if (get && signingOn_) {
    refused("missing-signature");
    return forbidden("GET URLs must be signed here: append &sig=<base64url HMAC-SHA256 of the path and query>");
  }
  return std::nullopt;
}

std::map<std::string, std::string> Access::rateLimitHeaders(const ApiKey& key, const QuotaDecision& d) {
  // draft-ietf-httpapi-ratelimit-headers: the policy (quota q per window w seconds) and what is
  // left of it now (r units, t seconds until the bucket is full).
  return {{"RateLimit-Policy", "\"key\";q=" + number(key.perMinute) + ";w=60"},
          {"RateLimit", "\"key\";r=" + number(std::max(0.0, std::floor(d.remaining))) +
                            ";t=" + number(std::ceil(d.fullInS))}};
}

ApiError Access::quotaExceeded(const ApiKey& key, const QuotaDecision& d, double units) const {
  ApiError e{429,
             "quota-exceeded",
             "Too Many Requests",
             "this request costs " + number(units) + " quota units (1 per MiB of its estimated peak memory); "
             "the key '" + key.id + "' holds " + number(std::max(0.0, std::floor(d.remaining))) + " of its " +
                 number(key.burst) + ", refilled at " + number(key.perMinute) + " a minute",
             {},
             rateLimitHeaders(key, d)};
  e.headers["Retry-After"] = number(std::max(1.0, std::ceil(d.retryAfterS)));
  return e;
}

std::optional<ApiError> Access::enter(const ApiKey& key, std::shared_ptr<void>& place) {
  const int most = key.maxConcurrent > 0 ? key.maxConcurrent : config_.keyMaxConcurrent;
  {
    std::lock_guard lock(mutex_);
    PerKey& k = perKey_[key.id];
    if (k.inProgress >= most) {
      ++k.busy;
      return ApiError{429,
                      "too-many-concurrent",
                      "Too Many Requests",
                      "the key '" + key.id + "' has " + std::to_string(k.inProgress) + " requests in progress, the most it may (" +
                          (key.maxConcurrent > 0 ? "its maxConcurrent" : "--key-max-concurrent") + "): wait for one",
                      {},
                      {{"Retry-After", "1"}}};
    }
    ++k.inProgress;
  }
  place = std::shared_ptr<void>(nullptr, [this, id = key.id](void*) {
    std::lock_guard lock(mutex_);
    --perKey_[id].inProgress;
  });
  const QuotaDecision d = quota_.charge(key, 1, 1);
  {
    std::lock_guard lock(mutex_);
    PerKey& k = perKey_[key.id];
    if (d.allowed)
      k.units += 1;
    else
      ++k.limited;
  }
  if (d.allowed) return std::nullopt;
  place.reset();  // takes mutex_ itself
  return quotaExceeded(key, d, 1);
}

void Access::charge(const ApiKey& key, double units, httplib::Response& res) {
  // The bucket held min(units, burst) before the first unit: min(units, burst) - 1 after it.
  const QuotaDecision d = quota_.charge(key, units - 1, std::min(units, key.burst) - 1);
  {
    std::lock_guard lock(mutex_);
    PerKey& k = perKey_[key.id];
    ++(d.allowed ? k.allowed : k.limited);
    if (d.allowed) k.units += units - 1;
  }
  if (!d.allowed) throw quotaExceeded(key, d, units);
  for (const auto& [name, value] : rateLimitHeaders(key, d)) res.set_header(name, value);
}

void Access::refund(const ApiKey& key, double units) {
  if (units <= 1) return;
  quota_.charge(key, -(units - 1), Quota::kAlways);
  std::lock_guard lock(mutex_);
  perKey_[key.id].units -= units - 1;
}

void Access::chargeInvalid(const ApiKey& key, size_t bodyBytes) {
  const double units = quotaUnits(bodyBytes);
  if (units > 1) quota_.charge(key, units - 1, Quota::kAlways);
  std::lock_guard lock(mutex_);
  PerKey& k = perKey_[key.id];
  ++k.invalid;
  k.units += units - 1;
}

std::string Access::reload() {
  std::string error;
  std::vector<std::string> signingKeys;
  std::vector<ApiKey> apiKeys;
  if (signingOn_) error = UrlSigning::read(config_.urlSigningKeyFile, signingKeys);
  if (error.empty() && keysOn_) error = ApiKeys::read(config_.apiKeysFile, apiKeys);
  std::lock_guard lock(mutex_);
  if (!error.empty()) {
    ++failedReloads_;
    return error;
  }
  if (signingOn_) signing_.setKeys(std::move(signingKeys));
  if (keysOn_) keys_.set(std::move(apiKeys));
  ++reloads_;
  return "";
}

std::string Access::metricsText() const {
  std::lock_guard lock(mutex_);
  std::string out =
      "# HELP effectd_key_requests_total Requests made with each API key, by outcome (allowed; limited: 429 "
      "for quota; busy: 429 for maxConcurrent; invalid: 400, charged by body size).\n"
      "# TYPE effectd_key_requests_total counter\n";
  for (const auto& [id, k] : perKey_)
    for (const auto& [outcome, n] : {std::pair{"allowed", k.allowed}, {"limited", k.limited}, {"busy", k.busy},
                                     {"invalid", k.invalid}})
      out += "effectd_key_requests_total{key=\"" + id + "\",outcome=\"" + outcome + "\"} " + std::to_string(n) + "\n";
  out += "# HELP effectd_key_units_total Quota units charged to each API key.\n# TYPE effectd_key_units_total counter\n";
  for (const auto& [id, k] : perKey_) out += "effectd_key_units_total{key=\"" + id + "\"} " + number(k.units) + "\n";
  out += "# HELP effectd_access_refused_total Requests refused before their body was read, by reason.\n"
         "# TYPE effectd_access_refused_total counter\n";
  for (const auto& [reason, n] : refusals_)
    out += "effectd_access_refused_total{reason=\"" + reason + "\"} " + std::to_string(n) + "\n";
  out += "# HELP effectd_access_reloads_total Key files reread on SIGHUP, by result.\n"
         "# TYPE effectd_access_reloads_total counter\n"
         "effectd_access_reloads_total{result=\"ok\"} " + std::to_string(reloads_) + "\n" +
         "effectd_access_reloads_total{result=\"kept-old\"} " + std::to_string(failedReloads_) + "\n";
  const Quota::Counts q = quota_.counts();
  out += "# HELP effectd_quota_charges_total Quota charges by where they were kept: Redis (shared) or this "
         "process (local, also when Redis did not answer).\n# TYPE effectd_quota_charges_total counter\n"
         "effectd_quota_charges_total{store=\"redis\"} " + std::to_string(q.shared) + "\n" +
         "effectd_quota_charges_total{store=\"local-fallback\"} " + std::to_string(q.fallbacks) + "\n";
  return out;
}

}  // namespace effectd
