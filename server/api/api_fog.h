// POST /v1/fog: fog tables with their error, local fog regions (proto/schemas/fog.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/fog.h>

#include "api/requests.h"
#include "http/service.h"

namespace effectd {

void addFogEndpoints(Service& service);
// The endpoint's two steps (http/service.h, twoSteps), and both at once (a scene's part).
FogRequest parseFogRequest(const nlohmann::json& body, const RequestContext& ctx);
JsonReply runFog(const FogRequest& request, const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleFog(const nlohmann::json& body, const RequestContext& ctx);

}  // namespace effectd
