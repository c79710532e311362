#include "http/api_keys.h"

#include <algorithm>
#include <cmath>
#include <fstream>
#include <set>
#include <sstream>

#include <nlohmann/json.hpp>

#include "contract/codec.h"

namespace effectd {

bool ApiKey::allows(const std::string& path) const {
  return endpoints.empty() || std::find(endpoints.begin(), endpoints.end(), path) != endpoints.end();
}

std::string ApiKeys::read(const std::string& path, std::vector<ApiKey>& keys) {
  std::ifstream in(path);
  if (!in) return "cannot read the API key file " + path;
  std::stringstream text;
  text << in.rdbuf();
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text.str());
  } catch (const std::exception& e) {
    return path + " is not JSON: " + e.what();
  }
  if (!doc.is_object() || !doc.contains("keys") || !doc["keys"].is_array())
    return path + ": /keys must be an array of keys";
  keys.clear();
  std::set<std::string> ids, hashes;
  for (size_t i = 0; i < doc["keys"].size(); ++i) {
    const auto& k = doc["keys"][i];
    const std::string at = path + ": /keys/" + std::to_string(i);
    if (!k.is_object()) return at + " must be an object";
    ApiKey key;
    if (!k.contains("id") || !k["id"].is_string() || k["id"].get<std::string>().empty())
      return at + "/id must be a non-empty string";
    key.id = k["id"];
    if (key.id.find_first_of("\"\\\n") != std::string::npos) return at + "/id must not hold quotes, backslashes or newlines";
    if (!k.contains("sha256") || !k["sha256"].is_string()) return at + "/sha256 must be 64 hex digits";
    key.sha256 = k["sha256"];
    std::transform(key.sha256.begin(), key.sha256.end(), key.sha256.begin(), ::tolower);
    if (key.sha256.size() != 64 || key.sha256.find_first_not_of("0123456789abcdef") != std::string::npos)
      return at + "/sha256 must be 64 hex digits (the SHA-256 of the secret)";
    for (const char* field : {"perMinute", "burst"}) {
      if (!k.contains(field) || !k[field].is_number() || !(k[field].get<double>() > 0) ||
          !std::isfinite(k[field].get<double>()))
        return at + "/" + field + " must be a number > 0 (quota units)";
    }
    key.perMinute = k["perMinute"];
    key.burst = k["burst"];
    if (k.contains("endpoints")) {
      if (!k["endpoints"].is_array()) return at + "/endpoints must be an array of paths";
      for (const auto& e : k["endpoints"]) {
        if (!e.is_string() || e.get<std::string>().rfind("/v1/", 0) != 0)
          return at + "/endpoints must hold paths such as \"/v1/fog\"";
        key.endpoints.push_back(e);
      }
    }
    if (k.contains("maxConcurrent")) {
      if (!k["maxConcurrent"].is_number_integer() || k["maxConcurrent"].get<long long>() < 1 ||
          k["maxConcurrent"].get<long long>() > 100000)
        return at + "/maxConcurrent must be an integer from 1 to 100000";
      key.maxConcurrent = k["maxConcurrent"].get<int>();
    }
    if (k.contains("maxStreams")) {
      if (!k["maxStreams"].is_number_integer() || k["maxStreams"].get<long long>() < 1 ||
          k["maxStreams"].get<long long>() > 100000)
        return at + "/maxStreams must be an integer from 1 to 100000";
      key.maxStreams = k["maxStreams"].get<int>();
    }
    if (!ids.insert(key.id).second) return at + "/id repeats the id '" + key.id + "'";
    if (!hashes.insert(key.sha256).second) return at + "/sha256 repeats another key's secret";
    keys.push_back(std::move(key));
  }
  return "";
}

void ApiKeys::set(std::vector<ApiKey> keys) {
  auto next = std::make_shared<const std::vector<ApiKey>>(std::move(keys));
  std::lock_guard lock(mutex_);
  keys_ = std::move(next);
}

bool ApiKeys::enabled() const {
  std::lock_guard lock(mutex_);
  return !keys_->empty();
}

std::optional<ApiKey> ApiKeys::find(const std::string& secret) const {
  std::shared_ptr<const std::vector<ApiKey>> keys;
  {
    std::lock_guard lock(mutex_);
    keys = keys_;
  }
  const std::string hash = sha256Hex(secret);
  std::optional<ApiKey> found;
  for (const auto& k : *keys)  // every key compared, in constant time each
    if (constantTimeEqual(k.sha256, hash)) found = k;
  return found;
}

}  // namespace effectd
