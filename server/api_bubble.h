// POST /v1/bubble: the soap bubble's uniforms, shaders, mesh and thin-film table
// (proto/schemas/bubble.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/bubble.h>

#include "service.h"

namespace effectd {

void addBubbleEndpoints(Service& service);
JsonReply handleBubble(const nlohmann::json& body, const RequestContext& ctx);
effects::bubble::Params parseBubbleParams(const nlohmann::json& j);
effects::bubble::Features parseBubbleFeatures(const nlohmann::json& j);
effects::bubble::ThinFilmOptions thinFilmOptions(const nlohmann::json& body, const effects::bubble::Params& params,
                                                 const Config& config);  // throws 413 over --max-thin-film-texels
// What /v1/bubble answers when the body has no "include" list (the handler and costs.cpp).
inline const std::vector<std::string> kBubbleIncludes = {"uniforms", "shader"};

}  // namespace effectd
