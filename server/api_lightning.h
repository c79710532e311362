// POST /v1/lightning: bolts grown on a grid around obstacles (proto/schemas/lightning.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/lightning.h>

#include "lightning_volume.h"
#include "service.h"

namespace effectd {

void addLightningEndpoints(Service& service);
JsonReply handleLightning(const nlohmann::json& body, const RequestContext& ctx);
struct LightningRequest {
  effects::lightning::Params params;
  effects::lightning::ShapeParams shape;
  effects::lightning::TimelineParams timeline;  // animationSeed, timeScale, "timeline"
  World world;                                  // 3-D: where the grid lies ("world")
};
// The request at JSON pointer `at` ("" for the endpoint's body); problems name fields under it.
LightningRequest parseLightning(const nlohmann::json& body, const Config& config, const std::string& at);
effects::lightning::Bolt growBolt(const effects::lightning::Params& params, const std::string& at);  // throws ApiError
// What /v1/lightning answers when the body has no "include" list (the handler and costs.cpp).
inline const std::vector<std::string> kLightningIncludes = {"polylines"};

}  // namespace effectd
