// JSON scenes (proto/schemas/scene.json) -> render::Scene, shared by POST /v1/render and
// the command line (`effectd render scene.json -o out.png`).
#pragma once

#include <render/render.h>
#include <nlohmann/json.hpp>

#include "config.h"
#include "service.h"

namespace effectd {

// Computes every effect the scene contains (bolt, bubble mesh, thin-film table) and decodes
// images. Throws ApiError naming the field, with pointers from the scene's root.
effects::render::Scene buildScene(const nlohmann::json& body, const RequestContext& ctx, double* computeMs = nullptr);

}  // namespace effectd
