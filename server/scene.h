// JSON scenes (proto/schemas/scene.json) -> render::Scene, shared by POST /v1/render and
// the command line (`effectd render scene.json -o out.png`).
#pragma once

#include <render/render.h>
#include <nlohmann/json.hpp>

#include "config.h"
#include "service.h"

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

// Computes every effect the scene contains (bolt, bubble mesh, thin-film table) and decodes
// images. Throws ApiError naming the field, with pointers from the scene's root. With
// `animation`, also what an animated render ("frames") needs.
effects::render::Scene buildScene(const nlohmann::json& body, const RequestContext& ctx, double* computeMs = nullptr,
                                  Animation* animation = nullptr);

// An animated render's bytes: a looping GIF or a flipbook PNG, and the headers that describe it.
struct Movie {
  std::string bytes, contentType;
  std::vector<std::pair<std::string, std::string>> headers;
};

// Renders `animation`'s frames into a Movie: hand sequence() to a renderer, then finish().
class MovieWriter {
 public:
  // `parallel` writes a flipbook's PNG (null: the calling thread only).
  MovieWriter(const Animation& animation, int width, int height, int bitDepth, effects::Parallel* parallel);
  effects::render::Sequence sequence();
  effects::Result<Movie> finish();
  // Time spent encoding: each frame into the GIF or the sheet (on the render thread), and finish.
  double encodeMs() const { return encodeMs_; }

 private:
  const Animation& animation_;
  int bitDepth_;
  effects::Parallel* parallel_;
  double encodeMs_ = 0;
  effects::Result<Movie> write();  // finish() without the stopwatch
  std::optional<effects::render::GifEncoder> gif_;
  std::optional<effects::render::Flipbook> book_;
};

}  // namespace effectd
