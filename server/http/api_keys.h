// API keys (--api-keys FILE): who may ask, and how much. The file holds only each secret's
// SHA-256, so that reading it gives no key away:
//   {"keys": [{"id": "game-a", "sha256": "<64 hex digits>", "perMinute": 600, "burst": 120,
//              "endpoints": ["/v1/fog", "/v1/lightning"], "maxConcurrent": 4}]}
// perMinute and burst are quota units (quota.h); endpoints is optional (absent = all);
// maxConcurrent is optional (absent = --key-max-concurrent): the key's requests in progress at
// once on one replica, so that one key cannot fill the admission queue and heavy slots;
// maxStreams is optional (absent = --key-max-streams): its job event streams at once
// (http/streams.h).
#pragma once

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

namespace effectd {

struct ApiKey {
  std::string id;
  std::string sha256;  // of the secret, lower-case hex
  double perMinute = 0, burst = 0;
  std::vector<std::string> endpoints;  // empty = every endpoint
  int maxConcurrent = 0;               // 0 = the server's --key-max-concurrent
  int maxStreams = 0;                  // job event streams at once; 0 = the server's --key-max-streams

  bool allows(const std::string& path) const;
};

class ApiKeys {
 public:
  // Reads and checks the file. Returns "" or what is wrong with it (the field named).
  static std::string read(const std::string& path, std::vector<ApiKey>& keys);

  void set(std::vector<ApiKey> keys);  // safe while requests are checked
  bool enabled() const;
  // The key whose secret is `secret`, if any.
  std::optional<ApiKey> find(const std::string& secret) const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const std::vector<ApiKey>> keys_ = std::make_shared<std::vector<ApiKey>>();
};

}  // namespace effectd
