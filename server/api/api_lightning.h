// POST /v1/lightning: bolts grown on a grid around obstacles (proto/schemas/lightning.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/lightning.h>

#include "api/lightning_volume.h"
#include "api/requests.h"
#include "http/service.h"

namespace effectd {

void addLightningEndpoints(Service& service);
// The endpoint's two steps (http/service.h, twoSteps), and both at once (a scene's part).
LightningRequest parseLightningRequest(const nlohmann::json& body, const RequestContext& ctx);
JsonReply runLightning(const LightningRequest& request, const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleLightning(const nlohmann::json& body, const RequestContext& ctx);
// The bolt's parameters, completed by the heavy step: the obstacles and the region drawn (a
// mesh voxelised), the calibration for them, and the variant's and the request's overrides.
effects::lightning::Params boltParams(const LightningRequest& request, const std::string& at);
// Grows the bolt; throws ApiError. With `progress` (a job's), reports to it and stops when it says so.
effects::lightning::Bolt growBolt(effects::lightning::Params params, const std::string& at,
                                  const JobProgress& progress = {});

}  // namespace effectd
