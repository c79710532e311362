#include "api/api_common.h"

#include <algorithm>

#include <effects/common.h>

namespace effectd {

ApiError fieldError(int status, const std::string& pointer, const std::string& message) {
  return ApiError{status,
                  status == 413 ? "limit-exceeded" : "invalid-field",
                  status == 413 ? "Request exceeds a configured limit" : "Invalid field",
                  pointer + ": " + message,
                  {{pointer, message}},
                  {}};
}

glm::dvec3 toVec3(const nlohmann::json& j) { return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>()}; }

void requireNonZero(const glm::dvec3& v, const std::string& pointer) {
  if (v.x == 0 && v.y == 0 && v.z == 0) throw fieldError(400, pointer, "must not be the zero vector");
}

nlohmann::json statsJson(const effects::Stats& s) {
  nlohmann::json j = {{"method", s.method}, {"elapsedMs", s.elapsedMs}};
  if (!s.counters.empty()) j["counters"] = s.counters;
  if (s.error) {
    j["error"] = *s.error;
    if (!s.errorKind.empty()) j["errorKind"] = s.errorKind;
    j["errorMetric"] = s.errorMetric;
    j["reference"] = s.reference;
  }
  if (s.errorMs > 0) j["errorMs"] = s.errorMs;
  return j;
}

}  // namespace effectd
