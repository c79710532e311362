#include "http/url_signing.h"

#include <algorithm>
#include <cerrno>
#include <cstdlib>
#include <fstream>

#include "contract/codec.h"

namespace effectd {

namespace {
constexpr const char* kSig = "&sig=";
constexpr size_t kMaxKeys = 2;
}  // namespace

std::string UrlSigning::read(const std::string& path, std::vector<std::string>& keys) {
  std::ifstream in(path);
  if (!in) return "cannot read the URL signing key file " + path;
  keys.clear();
  std::string line;
  while (std::getline(in, line)) {
    const size_t a = line.find_first_not_of(" \t\r"), b = line.find_last_not_of(" \t\r");
    if (a == std::string::npos) continue;
    keys.push_back(line.substr(a, b - a + 1));
  }
  if (keys.empty()) return "the URL signing key file " + path + " holds no key";
  if (keys.size() > kMaxKeys) return "the URL signing key file " + path + " holds more than two keys";
  for (const auto& k : keys)
    if (k.size() < 16) return "a URL signing key in " + path + " is shorter than 16 characters";
  return "";
}

std::string UrlSigning::sign(const std::string& key, const std::string& target) {
  return base64UrlEncode(hmacSha256(key, target));
}

void UrlSigning::setKeys(std::vector<std::string> keys) {
  auto next = std::make_shared<const std::vector<std::string>>(std::move(keys));
  std::lock_guard lock(mutex_);
  keys_ = std::move(next);
}

bool UrlSigning::enabled() const {
  std::lock_guard lock(mutex_);
  return !keys_->empty();
}

bool UrlSigning::carriesSignature(const std::string& target) const {
  return target.find(kSig) != std::string::npos;
}

std::string UrlSigning::verify(const std::string& target, long long now) const {
  std::shared_ptr<const std::vector<std::string>> keys;
  {
    std::lock_guard lock(mutex_);
    keys = keys_;
  }
  const size_t at = target.rfind(kSig);
  if (at == std::string::npos) return "the URL carries no sig parameter (signed URLs are required here)";
  const std::string signedPart = target.substr(0, at), sig = target.substr(at + std::string(kSig).size());
  if (sig.find('&') != std::string::npos) return "sig must be the URL's last parameter";
  const auto mac = base64UrlDecode(sig);
  if (!mac || mac->size() != 32) return "sig is not a base64url HMAC-SHA256";
  bool valid = false;
  for (const auto& key : *keys) valid = constantTimeEqual(hmacSha256(key, signedPart), *mac) || valid;
  if (!valid) return "sig does not match the URL under any signing key";
  // exp, when present, is one of the signed parameters.
  const size_t q = signedPart.find('?');
  for (size_t pos = q == std::string::npos ? signedPart.size() : q + 1; pos < signedPart.size();) {
    const size_t end = std::min(signedPart.find('&', pos), signedPart.size());
    const std::string param = signedPart.substr(pos, end - pos);
    if (param.rfind("exp=", 0) == 0) {
      const std::string value = param.substr(4);
      char* stop = nullptr;
      errno = 0;
      const long long exp = std::strtoll(value.c_str(), &stop, 10);
      if (value.empty() || *stop != '\0' || errno) return "exp is not a Unix time in seconds";
      if (now > exp) return "the URL expired at " + value + " (now " + std::to_string(now) + ")";
    }
    pos = end + 1;
  }
  return "";
}

}  // namespace effectd
