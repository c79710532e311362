#include "http/etag.h"

#include "contract/codec.h"
#include "contract/config.h"

namespace effectd {

using nlohmann::json;

bool asksForTimings(const json& j) {
  if (j.is_object()) {
    for (const auto& [key, value] : j.items()) {
      if (key == "include" && value.is_array())
        for (const auto& v : value)
          if (v == "stats") return true;
      if (asksForTimings(value)) return true;
    }
  } else if (j.is_array()) {
    for (const auto& v : j)
      if (asksForTimings(v)) return true;
  }
  return false;
}

bool etagMatches(const std::string& ifNoneMatch, const std::string& etag) {
  if (ifNoneMatch.empty()) return false;
  size_t pos = 0;
  while (pos < ifNoneMatch.size()) {
    size_t end = ifNoneMatch.find(',', pos);
    if (end == std::string::npos) end = ifNoneMatch.size();
    std::string tag = ifNoneMatch.substr(pos, end - pos);
    tag.erase(0, tag.find_first_not_of(" \t"));
    tag.erase(tag.find_last_not_of(" \t") + 1);
    if (tag.rfind("W/", 0) == 0) tag.erase(0, 2);
    if (tag == "*" || tag == etag) return true;
    pos = end + 1;
  }
  return false;
}

std::string etagFor(const std::string& path, const std::string& salt, const std::string& canonical, Coding coding) {
  std::string identity = buildVersion();
  for (const std::string* part : {&path, &salt, &canonical}) identity.append("\n").append(*part);
  std::string tag = "\"";
  tag.append(sha256Hex(identity), 0, 32);
  if (coding != Coding::kIdentity) tag.append("-").append(codingName(coding));
  return tag.append("\"");
}

}  // namespace effectd
