#include "api/requests.h"

#include <algorithm>

namespace effectd {

Includes::Includes(const nlohmann::json& body, std::vector<std::string> defaults) : items_(std::move(defaults)) {
  if (auto it = body.find("include"); it != body.end()) {
    items_.clear();
    for (const auto& v : *it) items_.push_back(v.get<std::string>());
  }
}

bool Includes::has(const std::string& what) const {
  return std::find(items_.begin(), items_.end(), what) != items_.end();
}

}  // namespace effectd
