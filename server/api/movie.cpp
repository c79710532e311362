// A scene into bytes: a still into a PNG; an animation, each frame's scene from the animation,
// into a GIF or a flipbook.
#include "api/movie.h"

namespace effectd {

namespace rd = effects::render;

MovieWriter::MovieWriter(const Animation& animation, int width, int height, int bitDepth,
                         effects::Parallel* parallel)
    : animation_(animation), bitDepth_(bitDepth), parallel_(parallel) {
  if (animation.frames.flipbook)
    book_.emplace(width, height, animation.frames.count);
  else
    gif_.emplace(width, height, animation.frames.count, animation.frames.fps, parallel);
}

rd::Sequence MovieWriter::sequence() {
  rd::Sequence s;
  s.count = animation_.frames.count;
  s.prepare = [this](rd::Scene& scene, int i) {
    const Animation& a = animation_;
    const double dt = 1.0 / a.frames.fps, offset = i * dt;
    scene.time = a.time + offset;
    for (size_t k = 0; k < scene.bubbles.size() && k < a.bubbleTimes.size(); ++k) {
      scene.bubbles[k].time = a.bubbleTimes[k] + offset;
      // The film at this frame's time, on the thread pool (the first frame's was checked when
      // the scene was built; should this one fail, the frame computes it and says why).
      rd::Bubble& b = scene.bubbles[k];
      if (!b.thickness || b.thicknessTime != b.time) (void)rd::prepareThickness(b, parallel_);
    }
    if (scene.lightning && a.strike) {
      // The strike as an eye sees it: each vertex at its brightest moment in the frame.
      const double t = scene.time - a.strikeTime;
      scene.lightning->polylines = effects::lightning::exposure(*a.strike, a.bolt, t, t + dt);
    }
  };
  s.consume = [this](const rd::Frame& frame, int i) -> std::optional<effects::Error> {
    effects::Stopwatch watch;
    std::optional<effects::Error> e;
    if (book_)
      book_->put(frame.image, i);
    else
      e = gif_->add(frame.image);
    encodeMs_ += watch.ms();
    return e;
  };
  return s;
}

effects::Result<Movie> MovieWriter::finish() {
  effects::Stopwatch watch;
  auto movie = write();
  encodeMs_ += watch.ms();
  return movie;
}

effects::Result<Movie> MovieWriter::write() {
  Movie m;
  const Frames& f = animation_.frames;
  // A GIF plays at 100 / delay frames per second (whole hundredths); a flipbook at the rate asked.
  const double rate = book_ ? f.fps : 100.0 / rd::gifDelay(f.fps);
  m.headers = {{"X-Frame-Count", std::to_string(f.count)}, {"X-Frame-Rate", nlohmann::json(rate).dump()}};
  if (book_) {
    auto png = rd::encodePng(book_->sheet, bitDepth_, parallel_);
    if (!png.ok()) return png.error();
    m.bytes = std::move(png.value());
    m.contentType = "image/png";
    m.headers.push_back({"X-Flipbook-Columns", std::to_string(book_->columns)});
    m.headers.push_back({"X-Flipbook-Rows", std::to_string(book_->rows)});
    return m;
  }
  auto gif = gif_->finish();
  if (!gif.ok()) return gif.error();
  m.bytes = std::move(gif.value());
  m.contentType = "image/gif";
  return m;
}

effects::Result<Rendered> renderScene(rd::Scene scene, const Animation& animation, effects::Parallel* parallel,
                                      const DrawScene& draw) {
  Rendered r;
  const int bitDepth = scene.bitDepth;
  if (animation.frames.count > 0) {
    MovieWriter writer(animation, scene.width, scene.height, bitDepth, parallel);
    const rd::Sequence sequence = writer.sequence();
    auto frames = draw(std::move(scene), &sequence);
    if (!frames.ok()) return frames.error();
    r.frame = std::move(frames.value());
    auto movie = writer.finish();
    if (!movie.ok()) return movie.error();
    r.output = std::move(movie.value());
    r.encodeMs = writer.encodeMs();
    return r;
  }
  auto frame = draw(std::move(scene), nullptr);
  if (!frame.ok()) return frame.error();
  r.frame = std::move(frame.value());
  effects::Stopwatch encode;
  auto png = rd::encodePng(r.frame.image, bitDepth, parallel);
  if (!png.ok()) return png.error();
  r.output.bytes = std::move(png.value());
  r.output.contentType = "image/png";
  r.encodeMs = encode.ms();
  return r;
}

}  // namespace effectd
