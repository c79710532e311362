// Who may ask for effects, and how much (docs/serving.md, "Facing the internet"): signed URLs
// (url_signing.h), API keys (api_keys.h) and their quotas (quota.h), around the effect
// endpoints. Without --url-signing-key-file and --api-keys the service is open, as before.
//
//   GET with sig            the signature must hold (else 403); no key is needed or charged
//   GET without sig         signing on and no keys: 403; keys on: as a POST
//   POST                    keys on: Authorization: Bearer <secret> (none: 401 with
//                           WWW-Authenticate; unknown, or not for this endpoint: 403), and
//                           the key's bucket is charged the request's units (over: 429)
#pragma once

#include <map>
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
  // (with `key` set when it came with one). `now` in Unix seconds.
  std::optional<ApiError> check(const httplib::Request& req, const std::string& route, long long now,
                                std::optional<ApiKey>& key);
  // Charges `key` `units`, sets the RateLimit headers on `res`; throws a 429 ApiError when its
  // bucket does not hold them.
  void charge(const ApiKey& key, double units, httplib::Response& res);
  // SIGHUP: rereads both files. "" when done, else why the old keys stay.
  std::string reload();
  std::string metricsText() const;
  bool open() const { return !signingOn_ && !keysOn_; }

 private:
  void refused(const std::string& reason);

  const Config& config_;
  bool signingOn_ = false, keysOn_ = false;
  UrlSigning signing_;
  ApiKeys keys_;
  Quota quota_;
  mutable std::mutex mutex_;
  struct PerKey {
    unsigned long long allowed = 0, limited = 0;
    double units = 0;
  };
  std::map<std::string, PerKey> perKey_;
  std::map<std::string, unsigned long long> refusals_;  // by reason
  unsigned long long reloads_ = 0, failedReloads_ = 0;
};

}  // namespace effectd
