// POST /v1/lightning: bolts grown on a grid around obstacles (proto/schemas/lightning.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/lightning.h>

#include "service.h"

namespace effectd {

void addLightningEndpoints(Service& service);
JsonReply handleLightning(const nlohmann::json& body, const RequestContext& ctx);
struct LightningRequest {
  effects::lightning::Params params;
  effects::lightning::ShapeParams shape;
};
LightningRequest parseLightning(const nlohmann::json& body, const Config& config);
effects::lightning::Bolt growBolt(const effects::lightning::Params& params);  // throws ApiError
// What /v1/lightning answers when the body has no "include" list (the handler and costs.cpp).
inline const std::vector<std::string> kLightningIncludes = {"polylines"};

}  // namespace effectd
