// What each endpoint's request costs before it runs (admission.h): its peak bytes, read off
// the sizes in the body, and whether it is heavy. The per-unit figures are measured peaks
// (bench/memory_estimates.py prints estimate against measured peak RSS for each endpoint,
// and the estimates are kept at or above the measurements); the request body's own bytes are
// reserved separately by the service before the body is read.
#pragma once

#include <string>

#include <nlohmann/json.hpp>

#include "config.h"
#include "service.h"

namespace effectd {

Cost fogCost(const nlohmann::json& body, const Config& config);
Cost lightningCost(const nlohmann::json& body, const Config& config);
Cost tangentsCost(const nlohmann::json& body, const Config& config);
Cost glbCost(const std::string& body, const Config& config);
Cost bubbleCost(const nlohmann::json& body, const Config& config);
Cost sceneCost(const nlohmann::json& body, const Config& config);   // /v1/scene: the effects' JSON
Cost renderCost(const nlohmann::json& body, const Config& config);  // /v1/render: effects + frame

}  // namespace effectd
