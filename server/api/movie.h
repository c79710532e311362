// A scene into bytes, for POST /v1/render and `effectd render`: a still into a PNG, an
// animation (scene.h's Animation) frame by frame into a looping GIF or a flipbook PNG.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <render/render.h>

#include "api/scene.h"

namespace effectd {

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

// A scene drawn into bytes: what the renderer said of the draw, and the encoded result (a PNG
// for a still; with frames the movie, a GIF or a flipbook PNG, and its headers).
struct Rendered {
  effects::render::Frame frame;  // timings, passes, variants compiled (the image: a still's only)
  Movie output;
  double encodeMs = 0;
};
// How to draw: a still (`sequence` null) or every frame of a sequence, on whatever renderer the
// caller has (the server's pool, the command line's own renderer).
using DrawScene = std::function<effects::Result<effects::render::Frame>(effects::render::Scene scene,
                                                                         const effects::render::Sequence* sequence)>;
// The one way a scene becomes bytes, for POST /v1/render and `effectd render`.
effects::Result<Rendered> renderScene(effects::render::Scene scene, const Animation& animation,
                                      effects::Parallel* parallel, const DrawScene& draw);

}  // namespace effectd
