// What every endpoint file shares: field problems, vectors from JSON, the "include" list,
// compact arrays, float rounding for the wire, stats as JSON.
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <glm/vec3.hpp>

#include "api/requests.h"
#include "http/service.h"

namespace effects {
struct Stats;
}

namespace effectd {

glm::dvec3 toVec3(const nlohmann::json& j);  // schema guarantees three numbers
void requireNonZero(const glm::dvec3& v, const std::string& pointer);  // 400 naming pointer
// A problem about one field: 400 invalid-field, 413 limit-exceeded, 422 (well-formed but
// impossible); detail "<pointer>: <message>", errors [{pointer, message}].
ApiError fieldError(int status, const std::string& pointer, const std::string& message);
// glm vectors as one flat JSON array (x0, y0, z0, x1, ...): the compact form meshes use.
template <int N, class V>
nlohmann::json flat(const std::vector<V>& v) {
  nlohmann::json a = nlohmann::json::array();
  a.get_ref<nlohmann::json::array_t&>().reserve(v.size() * N);
  for (const V& x : v)
    for (int c = 0; c < N; ++c) a.push_back(x[c]);
  return a;
}
// Rounds to float precision for the wire (geometry is float; see docs/architecture.md).
inline double wire(double v) { return static_cast<double>(static_cast<float>(v)); }
// Stats as JSON: {method, elapsedMs, counters, error, errorMetric, reference}.
nlohmann::json statsJson(const effects::Stats& stats);

}  // namespace effectd
