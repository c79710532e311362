// Who may ask for effects, and how much (docs/serving.md, "Facing the internet"): signed URLs
// (url_signing.h), API keys (api_keys.h) and their quotas (quota.h), around the effect
// endpoints. Without --url-signing-key-file and --api-keys the service is open, as before.
//
//   GET with sig            the signature must hold (else 403); no key is needed or charged
//   GET without sig         signing on and no keys: 403; keys on: as a POST
//   POST                    keys on: Authorization: Bearer <secret> (none: 401 with
//                           WWW-Authenticate; unknown, or not for this endpoint: 403), and
//                           the key's bucket is charged the request's units (over: 429)
//
// A key pays in steps, so that a key that cannot pay costs the server nothing: before its body
// is read, a request takes one of the key's maxConcurrent places and one unit (enter(); 429
// and the connection closed when either is missing); before admission, the rest of its units
// (charge(); admission refusing it gives them back: refund()); a body that fails parsing or
// the schema pays by its size, one unit a MiB, into debt if need be (chargeInvalid()).
#pragma once

#include <map>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "contract/config.h"
#include "contract/problem.h"
#include "http/api_keys.h"
#include "http/quota.h"
#include "http/url_signing.h"

namespace httplib {
struct Request;
struct Response;
}  // namespace httplib

namespace effectd {

class Access {
 public:
  // Reads the configured files; throws std::runtime_error naming what is wrong with them.
  explicit Access(const Config& config);

  // The request's right to ask, before its body is read: the problem that refuses it, or none
  // (with `key` set when it came with one). `now` in Unix seconds. On the jobs' routes
  // (`jobsRoute`) a GET is asked for a key as a POST is, never for a signature, and the key's
  // endpoints are checked against the effect a job runs when it is submitted (allows()).
  std::optional<ApiError> check(const httplib::Request& req, const std::string& route, long long now,
                                std::optional<ApiKey>& key, bool jobsRoute = false);
  // Before the body is read: one of the key's places and its first unit, held by `place` until
  // the request ends. The 429 problem that refuses it (RateLimit headers set), or none.
  std::optional<ApiError> enter(const ApiKey& key, std::shared_ptr<void>& place);
  // Charges the rest of a request of `units` in all (its first was paid on entry), sets the
  // RateLimit headers on `res`; throws a 429 ApiError when the bucket does not hold them.
  void charge(const ApiKey& key, double units, httplib::Response& res);
  // Gives back what charge() took for a request admission then refused (`units` in all).
  void refund(const ApiKey& key, double units);
  // A body that failed parsing or the schema: its size in units, less the one paid on entry.
  void chargeInvalid(const ApiKey& key, size_t bodyBytes);
  // SIGHUP: rereads both files. "" when done, else why the old keys stay.
  std::string reload();
  std::string metricsText() const;
  bool open() const { return !signingOn_ && !keysOn_; }
  // Whether the quotas are shared through Redis (keys on and --quota-redis), its state for
  // /readyz ("" = answering) and its failed exchanges.
  bool sharedQuota() const { return keysOn_ && quota_.shared(); }
  std::string quotaStoreProblem() const { return quota_.storeProblem(); }
  uint64_t quotaStoreFailures() const { return quota_.storeFailures(); }

 private:
  void refused(const std::string& reason);
  // The RateLimit headers of `d` (draft-ietf-httpapi-ratelimit-headers).
  static std::map<std::string, std::string> rateLimitHeaders(const ApiKey& key, const QuotaDecision& d);
  ApiError quotaExceeded(const ApiKey& key, const QuotaDecision& d, double units) const;

  const Config& config_;
  bool signingOn_ = false, keysOn_ = false;
  UrlSigning signing_;
  ApiKeys keys_;
  Quota quota_;
  mutable std::mutex mutex_;
  struct PerKey {
    unsigned long long allowed = 0, limited = 0, busy = 0, invalid = 0;
    double units = 0;
    int inProgress = 0;
  };
  std::map<std::string, PerKey> perKey_;
  std::map<std::string, unsigned long long> refusals_;  // by reason
  unsigned long long reloads_ = 0, failedReloads_ = 0;
};

}  // namespace effectd
