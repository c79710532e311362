// The bubble's GPU shading variants (/v1/render's bubble pass) against the physical reference
// (render::referenceRender), on one scene: a bubble at t = 7 s reflecting a sky in front of a
// dark backdrop, mesh level 4, the wobble off (the reference traces the analytic sphere). The
// scene is built here through render/ as /v1/render builds it from the same request.
#include <fstream>

#include <effects/bubble.h>

#include "sections.h"

namespace report {

namespace {

namespace bb = effects::bubble;
namespace rd = effects::render;

struct Variant {
  std::string name;
  json request;  // the "bubble" of the /v1/render request
  bb::Features features;
};

std::vector<Variant> variants() {
  auto with = [](const char* shading, bool iridescence, bool backFace, bool highlight) {
    bb::Features f;
    f.wobble = false;
    f.shading = std::string(shading) == "paper" ? bb::Shading::kPaper : bb::Shading::kFilm;
    f.iridescence = iridescence, f.backFace = backFace, f.highlight = highlight;
    return f;
  };
  auto request = [](const char* shading, const json& features) {
    json f = {{"wobble", false}};
    f.update(features);
    return json{{"shading", shading}, {"features", f}, {"mesh", {{"level", 4}}}};
  };
  return {{"paper (eqns 3-11)", request("paper", json::object()), with("paper", false, true, true)},
          {"paper + film table", request("paper", {{"iridescence", true}}), with("paper", true, true, true)},
          {"film, near side", request("film", {{"backFace", false}, {"highlight", false}}), with("film", false, false, false)},
          {"film + far side", request("film", {{"highlight", false}}), with("film", false, true, false)},
          {"film + far side + highlight (default)", request("film", json::object()), with("film", false, true, true)}};
}

rd::Scene sceneOf(int size, const bb::Features& features) {
  rd::Scene s;
  s.width = s.height = size;
  s.time = 7;
  s.camera.position = {0, 0.3, 4};
  s.camera.target = {0, 0, 0};
  s.camera.fovYDeg = 45;
  s.background.kind = rd::Background::Kind::kGradient;
  s.background.top = {0.18, 0.24, 0.2, 1};
  s.background.bottom = {0.08, 0.1, 0.07, 1};
  s.environment = rd::Environment{{0.35, 0.6, 1.0}, {1.0, 0.98, 0.95}, {0.16, 0.18, 0.12}};
  rd::Bubble b;
  b.features = features;
  bb::MeshOptions mesh;
  mesh.level = 4;
  mesh.wobble = false;  // the vertex shader wobbles (eqn 11); here it is off
  b.mesh = std::make_shared<const bb::Mesh>(bb::icosphere(b.params, mesh).value());
  const bool film = features.shading == bb::Shading::kFilm;
  if (film) b.lights = {bb::Light{}};  // a request's default light
  if (film || features.iridescence) {
    bb::ThinFilmOptions tf;
    tf.ior = b.params.n2;
    tf.measureError = false;
    tf.thicknessMaxNm = film ? std::max({1000.0, b.film.bottomStartNm, b.film.bottomEndNm}) : 1000.0;  // the film's thickest
    b.thinFilm = std::make_shared<const bb::ThinFilmTable>(bb::thinFilmTable(tf).value());
    b.thinFilmRangeNm = {tf.thicknessMinNm, tf.thicknessMaxNm};
  }
  b.time = s.time;
  (void)rd::prepareThickness(b, nullptr);
  s.bubbles.push_back(std::move(b));
  return s;
}

int sizeOf(const Run& run) { return run.quick ? 96 : 512; }

// The frame times: each timing process makes its own renderer (a forked process cannot use the
// parent's), compiles each variant once untimed, then times the frames (read-back included);
// the reference's time, on two threads, likewise.
void measure(Run& run) {
  const int size = sizeOf(run), frames = run.quick ? 2 : 7;
  for (const Variant& v : variants()) {
    Row r;
    r.series = v.name;
    r.setting = v.request["shading"].get<std::string>();
    r.request = {{"bubble", v.request}};
    r.ticket = timeFrames(run, "render " + v.name, [size, f = v.features] { return sceneOf(size, f); }, frames);
    run.rows.push_back(r);
  }
  Row ref;
  ref.series = "reference (CPU, 400 wavelengths, 2 threads)";
  ref.setting = "physical";
  ref.request = {{"reference", true}};
  ref.errors["meanDeltaE"] = 0;
  ref.note = "0; 0";
  ref.ticket = run.time("render reference", [size, f = variants().back().features](int) {
    effects::ThreadPool pool(2);
    std::vector<double> ms;
    for (int i = 0; i < 2; ++i)
      if (auto r = rd::referenceRender(sceneOf(size, f), &pool); r.ok()) ms.push_back(r.value().ms);
    return ms;
  });
  run.rows.push_back(ref);
}

// The errors: each variant's frame (as its 8-bit PNG holds it) against the reference, and the
// pictures behind the numbers: the reference, the default's frame and its Delta E (grey =
// Delta E / 20, red > 20).
bool errors(Run& run, rd::Renderer& renderer) {
  const int size = sizeOf(run);
  const std::vector<Variant> vs = variants();
  effects::ThreadPool pool(2);
  auto ref = rd::referenceRender(sceneOf(size, vs.back().features), &pool);
  if (!ref.ok()) return std::fprintf(stderr, "error_report: render-bubble: %s\n", ref.error().message.c_str()), false;
  const rd::Reference& reference = ref.value();
  // Pixels at least 3 away from the silhouette, where the mesh's polygon edge cannot differ.
  std::vector<uint8_t> interior;
  for (size_t p = 0; p < reference.bubble.size(); ++p) {
    if (!reference.bubble[p]) continue;
    const int x = int(p % size_t(size)), y = int(p / size_t(size));
    bool all = x >= 3 && y >= 3 && x < size - 3 && y < size - 3;
    for (int dy = -3; dy <= 3 && all; ++dy)
      for (int dx = -3; dx <= 3 && all; ++dx) all = reference.bubble[size_t(y + dy) * size_t(size) + size_t(x + dx)];
    interior.push_back(all);
  }
  for (size_t i = 0; i < vs.size(); ++i) {
    auto f = renderer.render(sceneOf(size, vs[i].features));
    if (!f.ok()) return std::fprintf(stderr, "error_report: %s: %s\n", vs[i].name.c_str(), f.error().message.c_str()), false;
    const rd::Image frame = rd::Image{size, size, {}, rd::bytes8(f.value().image)};
    const std::vector<double> de = rd::bubbleDeltaE(frame, reference);
    std::vector<double> inside;
    for (size_t k = 0; k < de.size(); ++k)
      if (interior[k]) inside.push_back(de[k]);
    double mean = 0;
    for (double d : de) mean += d;
    Row& r = run.rows[i];
    r.errors["meanDeltaE"] = de.empty() ? NAN : mean / double(de.size());
    r.note = fmt(quantile(de, 0.95), 3) + "; " + fmt(quantile(inside, 0.95), 3);
    if (i + 1 < vs.size() || !run.timed) continue;
    rd::Image map{size, size, std::vector<float>(size_t(size) * size_t(size) * 4, 1.0f), {}};
    for (size_t p = 0, k = 0; p < reference.bubble.size(); ++p) {
      const double d = reference.bubble[p] ? de[k++] : 0.0;
      for (int c = 0; c < 3; ++c) map.rgba[p * 4 + size_t(c)] = float(std::min(d / 20, 1.0));
      if (d > 20) map.rgba[p * 4 + 1] = map.rgba[p * 4 + 2] = 0;
    }
    for (auto [name, img] : {std::pair{"bubble-reference.png", &reference.image}, {"bubble-frame.png", &frame},
                             {"bubble-delta-e.png", &map}}) {
      auto png = rd::encodePng(*img, 8);
      if (!png.ok()) return false;
      std::ofstream(run.pictures / name, std::ios::binary) << png.value();
    }
    run.pictureFiles = {{"the reference", "bubble-reference.png"},
                        {vs.back().name, "bubble-frame.png"},
                        {"ΔE*ab (grey = ΔE/20, red > 20)", "bubble-delta-e.png"}};
  }
  return true;
}

std::string conclude(const Section&, const Run& run) {
  const Row* best = nullptr;
  for (const Row& r : run.rows)
    if (errorOf(r, "meanDeltaE") > 0 && (!best || errorOf(r, "meanDeltaE") < errorOf(*best, "meanDeltaE"))) best = &r;
  if (!best) return "";
  return "Closest to the physical bubble: " + best->series + " (" + fmt(best->ms) + " ms, mean ΔE " +
         fmt(errorOf(*best, "meanDeltaE"), 3) + "), about " + fmt(run.rows.back().ms / std::max(best->ms, 1e-9), 2) +
         "× faster than the reference. The paper's model is a look, not a film: its refraction bends the backdrop as "
         "solid water would, and its film table is added without taking transmitted light away. The film model's "
         "error sits along the rim (grazing angles, the polygon silhouette, the left-out inside bounces).";
}

}  // namespace

Section renderBubbleSection() {
  Section s;
  s.id = "render-bubble";
  s.effect = "render";
  s.title = "Render previews: the bubble's shading against the CPU reference renderer";
  s.reference =
      "render::referenceRender: the analytic sphere ray traced on the CPU, the film per wavelength (400, 1 nm; Airy "
      "for s and p at the exact thickness of each point), the near film's reflection, the light through both films "
      "and the far film's reflection seen back through the near one (docs/rendering.md)";
  s.metrics = {{"meanDeltaE", "ΔE", "mean CIE76 ΔE*ab over the bubble's pixels", 5.0,
                "mean Delta E 5: the same colours side by side, but a visibly different bubble"}};
  s.timeName = "ms per 512² frame (median; 96² in the quick run)";
  s.settingName = "shading";
  s.noteName = "p95 ΔE*ab; p95 3 px inside the silhouette";
  s.code = {"render", "effects/bubble"};
  s.asks = {{"", "a 512² preview of a bubble (/v1/render)", {{"width", 512}, {"height", 512}}}};
  s.checkRelative = 2e-2, s.checkAbsolute = 0.05;  // llvmpipe rounds differently on another CPU
  s.measure = measure;
  s.afterTiming = errors;
  s.conclude = conclude;
  return s;
}

}  // namespace report
