// POST /v1/bubble: the soap bubble's uniforms, shaders, mesh and thin-film table
// (proto/schemas/bubble.json).
#pragma once

#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <effects/bubble.h>

#include "api/requests.h"
#include "http/service.h"

namespace effectd {

void addBubbleEndpoints(Service& service);
// The endpoint's two steps (http/service.h, twoSteps), and both at once (a scene's part).
BubbleRequest parseBubbleRequest(const nlohmann::json& body, const RequestContext& ctx);
JsonReply runBubble(const BubbleRequest& request, const nlohmann::json& body, const RequestContext& ctx);
JsonReply handleBubble(const nlohmann::json& body, const RequestContext& ctx);
// The thin-film table's thickness axis, nm: the body's thinFilm.thicknessRange, else [0, 1000],
// or up to the film's thickest for the film model.
nlohmann::json thicknessRange(const nlohmann::json& body, const effects::bubble::Features& f,
                              const effects::bubble::ThicknessOptions& film);
// A thin-film table's size: 413 over --max-thin-film-texels, naming pointer/thinFilm/width.
void checkThinFilmSize(const effects::bubble::ThinFilmOptions& o, const Config& config, const std::string& pointer);
// Where the icosphere's own parameters (level, radius) sit: under `at`/mesh.
FieldTable meshFields(const std::string& at);
// Icosphere subdivisions: the most a request may ask for (327 680 triangles), and the default
// of a rendered bubble (a /v1/bubble mesh defaults to MeshOptions{}.level).
inline constexpr int kMaxIcosphereLevel = 7;
inline constexpr int kRenderedIcosphereLevel = 4;

}  // namespace effectd
