// POST /v1/tangents: tangent frames for a JSON mesh, or for every triangle primitive of a
// binary glTF (proto/schemas/tangents.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "api/requests.h"
#include "http/service.h"

namespace effectd {

void addTangentsEndpoints(Service& service);
// The endpoint's two steps (http/service.h, twoSteps), and both at once (the fuzzer).
TangentsRequest parseTangentsRequest(const nlohmann::json& body, const RequestContext& ctx);
JsonReply runTangents(const TangentsRequest& request, const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleTangents(const nlohmann::json& body, const RequestContext& ctx);
BinaryReply handleGlb(const std::string& body, const RequestContext& ctx);  // model/gltf-binary

}  // namespace effectd
