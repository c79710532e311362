// POST /v1/tangents: tangent frames for a JSON mesh, or for every triangle primitive of a
// binary glTF (proto/schemas/tangents.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "service.h"

namespace effectd {

void addTangentsEndpoints(Service& service);
JsonReply handleTangents(const nlohmann::json& body, const RequestContext& ctx);
BinaryReply handleGlb(const std::string& body, const RequestContext& ctx);  // model/gltf-binary
// What /v1/tangents answers when the body has no "include" list (the handler and costs.cpp).
inline const std::vector<std::string> kTangentsIncludes = {"tangents", "remap", "indices"};

}  // namespace effectd
