// JSON scenes (proto/schemas/scene.json) -> render::Scene, shared by POST /v1/render and
// the command line (`effectd render scene.json -o out.png`); movie.h turns them into bytes.
#pragma once

#include <render/render.h>
#include <nlohmann/json.hpp>

#include "api/requests.h"
#include "contract/config.h"
#include "http/service.h"

namespace effectd {

// "frames": an animated render instead of one PNG.
struct Frames {
  int count = 0;  // 0 = a still
  double fps = 24;
  bool flipbook = false;  // one PNG sheet of frames instead of an animated GIF
};

// What moves from frame to frame: the scene's clock (surface wave, bubble wobble and flow)
// and the lightning strike (leader, strokes, flicker and fade).
struct Animation {
  Frames frames;
  double time = 0;                   // the scene's time at frame 0
  std::vector<double> bubbleTimes;  // each bubble's own time at frame 0 (its time, else the scene's)
  double strikeTime = 0;             // scene time at which the strike's leader sets off
  std::vector<effects::lightning::Polyline> bolt;
  std::optional<effects::lightning::Timeline> strike;
};

// Computes every effect the scene contains (bolt, bubble mesh, thin-film table) from its parts
// as their endpoints' parsers read them (request: api_render.h's parseRenderRequest), reads
// the scene's own fields (camera, quads, styles, frames) from its body, and decodes images.
// Throws ApiError naming the field, with pointers from the scene's root. With `animation`,
// also what an animated render ("frames") needs.
effects::render::Scene buildScene(const RenderRequest& request, const nlohmann::json& body, const RequestContext& ctx,
                                  double* computeMs = nullptr, Animation* animation = nullptr);

}  // namespace effectd
