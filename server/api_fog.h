// POST /v1/fog: fog tables with their error, local fog regions (proto/schemas/fog.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/fog.h>

#include "service.h"

namespace effectd {

void addFogEndpoints(Service& service);
JsonReply handleFog(const nlohmann::json& body, const RequestContext& ctx);
// A fog object / a region from the request; problems name fields under `pointer`.
effects::fog::Fog parseFog(const nlohmann::json& j, const std::string& pointer);
effects::fog::Region parseRegion(const nlohmann::json& j, const std::string& pointer);
// What /v1/fog answers when the body has no "include" list (the handler and costs.cpp).
inline const std::vector<std::string> kFogIncludes = {"table"};

}  // namespace effectd
