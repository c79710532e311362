// Signed URLs (--url-signing-key-file), as imgproxy and thumbor sign theirs: only URLs that the
// key's owner made get answered. A GET carries `sig`, the last parameter: the base64url (no
// padding) HMAC-SHA256, under one of the keys, of the path and query exactly as sent up to
// "&sig=". It may carry `exp` (Unix seconds) before it, which the signature covers.
#pragma once

#include <memory>
#include <mutex>
#include <string>
#include <vector>

namespace effectd {

class UrlSigning {
 public:
  // Reads the keys of `path`, one per non-empty line (surrounding spaces dropped), at most two
  // (the new and the old during a rotation). Returns "" or why it cannot.
  static std::string read(const std::string& path, std::vector<std::string>& keys);
  // `sig` for `target` ("/v1/fog?r=...&exp=..."): what a URL's owner appends as "&sig=".
  static std::string sign(const std::string& key, const std::string& target);

  void setKeys(std::vector<std::string> keys);  // safe while requests are verified
  bool enabled() const;
  bool carriesSignature(const std::string& target) const;
  // "" when `target` (path and query as sent) carries a valid sig under a key and, with exp, is
  // not past it at `now` (Unix seconds); else the reason, for a 403.
  std::string verify(const std::string& target, long long now) const;

 private:
  mutable std::mutex mutex_;
  std::shared_ptr<const std::vector<std::string>> keys_ = std::make_shared<std::vector<std::string>>();
};

}  // namespace effectd
