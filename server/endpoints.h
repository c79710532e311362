// Registration of the effect endpoints. Each api_<effect>.cpp turns validated JSON into
// library params, calls the library, and turns the result into the response body; nothing
// else about HTTP is its business.
#pragma once

#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include <effects/bubble.h>
#include <effects/fog.h>
#include <effects/lightning.h>

#include "service.h"

namespace effectd {

void addEffectEndpoints(Service& service);
void addFogEndpoints(Service& service);
void addLightningEndpoints(Service& service);
void addTangentsEndpoints(Service& service);
void addBubbleEndpoints(Service& service);
void addRenderEndpoints(Service& service);

// --- the effects' request handlers and parsers, reused by /v1/scene and /v1/render ---
JsonReply handleFog(const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleLightning(const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleBubble(const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleTangents(const nlohmann::json& body, const RequestContext& ctx);
BinaryReply handleGlb(const std::string& body, const RequestContext& ctx);  // model/gltf-binary
effects::fog::Fog parseFog(const nlohmann::json& j, const std::string& pointer);
effects::fog::Region parseRegion(const nlohmann::json& j, const std::string& pointer);
struct LightningRequest {
  effects::lightning::Params params;
  effects::lightning::ShapeParams shape;
};
LightningRequest parseLightning(const nlohmann::json& body, const Config& config);
effects::lightning::Bolt growBolt(const effects::lightning::Params& params);  // throws ApiError
effects::bubble::Params parseBubbleParams(const nlohmann::json& j);
effects::bubble::Features parseBubbleFeatures(const nlohmann::json& j);
effects::bubble::ThinFilmOptions thinFilmOptions(const nlohmann::json& body, const effects::bubble::Params& params,
                                                 const Config& config);  // throws 413 over --max-thin-film-texels

// --- helpers shared by the api_*.cpp files ---
glm::dvec3 toVec3(const nlohmann::json& j);  // schema guarantees three numbers
// A problem about one field: 400 invalid-field, 413 limit-exceeded, 422 (well-formed but
// impossible); detail "<pointer>: <message>", errors [{pointer, message}].
ApiError fieldError(int status, const std::string& pointer, const std::string& message);
// What each endpoint answers when the body has no "include" list (handlers and costs.cpp).
inline const std::vector<std::string> kFogIncludes = {"table"};
inline const std::vector<std::string> kLightningIncludes = {"polylines"};
inline const std::vector<std::string> kTangentsIncludes = {"tangents", "remap", "indices"};
inline const std::vector<std::string> kBubbleIncludes = {"uniforms", "shader"};
// The body's "include" list as a set test; `defaults` applies when "include" is absent.
class Includes {
 public:
  Includes(const nlohmann::json& body, std::vector<std::string> defaults);
  bool has(const std::string& what) const;

 private:
  std::vector<std::string> items_;
};
// glm vectors as one flat JSON array (x0, y0, z0, x1, ...): the compact form meshes use.
template <int N, class V>
nlohmann::json flat(const std::vector<V>& v) {
  nlohmann::json a = nlohmann::json::array();
  a.get_ref<nlohmann::json::array_t&>().reserve(v.size() * N);
  for (const V& x : v)
    for (int c = 0; c < N; ++c) a.push_back(x[c]);
  return a;
}
// Rounds to float precision for the wire (geometry is float; see architecture.md).
inline double wire(double v) { return static_cast<double>(static_cast<float>(v)); }

}  // namespace effectd

namespace effects { struct Stats; }
namespace effectd {
// Stats as JSON: {method, elapsedMs, counters, error, errorMetric, reference}.
nlohmann::json statsJson(const effects::Stats& stats);
}  // namespace effectd
