// What each endpoint's request costs before it runs (admission.h): its peak bytes, read off
// the sizes in the parsed request (requests.h), and whether it is heavy. The per-unit figures are measured peaks
// (bench/memory_estimates.py prints estimate against measured peak RSS for each endpoint,
// and the estimates are kept at or above the measurements); the request body's own bytes are
// reserved separately by the service before the body is read.
#pragma once

#include <string>

#include "api/requests.h"
#include "contract/config.h"
#include "http/service.h"

namespace effectd {

Cost fogCost(const FogRequest& request, const Config& config);
Cost lightningCost(const LightningRequest& request, const Config& config);
Cost tangentsCost(const TangentsRequest& request, const Config& config);
Cost glbCost(const std::string& body, const Config& config);  // the glTF's bytes, before they are read
Cost bubbleCost(const BubbleRequest& request, const Config& config);
Cost sceneCost(const SceneRequest& request, const Config& config);    // /v1/scene: the effects' JSON
Cost renderCost(const RenderRequest& request, const Config& config);  // /v1/render: effects + frame

}  // namespace effectd
