// POST /v1/render (a PNG of the scene) and POST /v1/scene (each effect's JSON), from the
// scene document (proto/schemas/scene.json); the scene itself is built in scene.h.
#pragma once

#include <cstddef>

#include <nlohmann/json.hpp>

#include "api/requests.h"
#include "http/service.h"

namespace effectd {

void addRenderEndpoints(Service& service);
// The scene's parts, each read by its endpoint's parser at its pointer (a bubble lit by the
// scene's lights when it has them), and a render's frame.
SceneRequest parseSceneRequest(const nlohmann::json& body, const RequestContext& ctx);
RenderRequest parseRenderRequest(const nlohmann::json& body, const RequestContext& ctx);
// The most pixels a `reference: true` render traces (400 wavelengths each).
inline constexpr size_t kMaxReferencePixels = 512 * 512;

}  // namespace effectd
