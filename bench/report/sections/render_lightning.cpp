// The lightning pass against its polylines: a bolt drawn with its glow off, every bright pixel
// of the core measured against the nearest segment of the answer's own polylines. The scene is
// built here through render/, as /v1/render builds it from the same request.
#include <glm/geometric.hpp>

#include <effects/lightning.h>

#include "sections.h"

namespace report {

namespace {

namespace lt = effects::lightning;
namespace rd = effects::render;

struct Variant {
  std::string name;
  int grid, frame;
  double coreWidth;
};

std::vector<Variant> variants(bool quick) {
  if (quick) return {{"64 grid, core 1.5", 64, 128, 1.5}};
  return {{"64 grid, core 1.5", 64, 256, 1.5}, {"64 grid, core 3", 64, 256, 3}, {"128 grid, core 1.5", 128, 512, 1.5}};
}

json requestOf(const Variant& v) {
  return {{"width", v.frame},
          {"height", v.frame},
          {"lightning",
           {{"grid", {{"width", v.grid}, {"height", v.grid}}}, {"start", {v.grid / 2, 0}}, {"targets", {{v.grid / 2, v.grid - 1}}}, {"seed", 5}}},
          {"lightningStyle", {{"coreWidth", v.coreWidth}, {"glowSigma", 0}}}};
}

rd::Scene sceneOf(const Variant& v) {
  lt::Params p;
  p.width = p.height = v.grid;
  p.start = {v.grid / 2, 0};
  p.targets = {{v.grid / 2, v.grid - 1}};
  p.seed = 5;
  lt::calibrate(p);  // as the server's default
  rd::Scene s;
  s.width = s.height = v.frame;
  s.background.color = {0, 0, 0, 1};
  rd::Lightning l;
  lt::ShapeParams shape;
  shape.jitterSeed = p.seed;  // a request's default: the bolt's seed
  l.polylines = lt::polylines(lt::grow(p).value(), shape);
  l.gridWidth = l.gridHeight = v.grid;
  l.coreWidth = v.coreWidth;
  l.glowSigma = 0;
  s.lightning = std::move(l);
  return s;
}

void measure(Run& run) {
  for (const Variant& v : variants(run.quick)) {
    Row r;
    r.series = v.name;
    r.setting = std::to_string(v.frame) + "², GPU";
    r.group = v.name;
    r.request = {{"lightningStyle", requestOf(v)["lightningStyle"]}};
    r.note = requestOf(v).dump();
    r.ticket = timeFrames(run, "render lightning " + v.name, [v] { return sceneOf(v); }, run.quick ? 2 : 7);
    run.rows.push_back(r);
  }
}

bool errors(Run& run, rd::Renderer& renderer) {
  const std::vector<Variant> vs = variants(run.quick);
  for (size_t i = 0; i < vs.size(); ++i) {
    const rd::Scene scene = sceneOf(vs[i]);
    auto f = renderer.render(scene);
    if (!f.ok()) return std::fprintf(stderr, "error_report: bolt %s did not render\n", vs[i].name.c_str()), false;
    const rd::Lightning& l = *scene.lightning;
    const int w = scene.width, h = scene.height;
    std::vector<std::pair<glm::dvec2, glm::dvec2>> segments;
    auto pixel = [&](const lt::Vertex& p) {
      return glm::dvec2((l.rect.x + p.x * (l.rect.z - l.rect.x) / l.gridWidth) * w,
                        (l.rect.y + p.y * (l.rect.w - l.rect.y) / l.gridHeight) * h);
    };
    for (const auto& line : l.polylines)
      for (size_t k = 1; k < line.vertices.size(); ++k) segments.push_back({pixel(line.vertices[k - 1]), pixel(line.vertices[k])});
    auto distance = [&](glm::dvec2 p) {
      double best = INFINITY;
      for (const auto& [a, b] : segments) {
        const glm::dvec2 ab = b - a;
        const double t = glm::dot(ab, ab) > 0 ? std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0) : 0.0;
        best = std::min(best, glm::length(p - (a + t * ab)));
      }
      return best;
    };
    const std::vector<uint8_t> px = rd::bytes8(f.value().image);
    auto blue = [&](int x, int y) { return px[(size_t(y) * size_t(w) + size_t(x)) * 4 + 2]; };
    double worst = 0;
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
        if (blue(x, y) >= 64) worst = std::max(worst, distance({x + 0.5, y + 0.5}) - l.coreWidth);
    int lit = 0;
    for (const auto& [a, b] : segments) {
      const glm::dvec2 m = 0.5 * (a + b);
      lit += blue(std::clamp(int(m.x), 0, w - 1), std::clamp(int(m.y), 0, h - 1)) >= 51;
    }
    run.rows[i].errors["maxOffsetPx"] = worst;
    run.rows[i].note = fmt(100.0 * lit / double(std::max<size_t>(1, segments.size())), 3) + " %";
  }
  return true;
}

std::string conclude(const Section& s, const Run& run) {
  return "Every bright pixel of the core lies within coreWidth + " + fmt(worstOf(run, "maxOffsetPx"), 3) + " px of the answer's polylines (the "
         "bound /v1/render states is " + fmt(s.metrics[0].limit) + " px: half a width of caps and one of anti-aliasing); "
         "the lit share of segment midpoints shows the bolt is drawn, not just kept inside.";
}

}  // namespace

Section renderLightningSection() {
  Section s;
  s.id = "render-lightning";
  s.effect = "render";
  s.title = "Render previews: the lightning pass against its polylines";
  s.reference =
      "the answer's own polylines, mapped to pixels by the scene's rect: every bright pixel of the core (blue >= 64 of "
      "255, glow off) measured against the nearest segment";
  s.metrics = {{"maxOffsetPx", "px", "max over bright pixels of (distance to the nearest segment − coreWidth), px", 1.75,
                "the bound /v1/render states: the core 1.75 px wider than coreWidth", "bound"}};
  s.timeName = "ms per frame (median)";
  s.settingName = "bolt";
  s.noteName = "segment midpoints lit";
  s.code = {"render", "effects/lightning"};
  s.asks = {{"128 grid, core 1.5", "a 512² preview of a bolt (/v1/render)", {{"width", 512}, {"height", 512}}}};
  s.checkRelative = 0, s.checkAbsolute = 0.5;  // llvmpipe rasterises differently on another CPU
  s.measure = measure;
  s.afterTiming = errors;
  s.conclude = conclude;
  return s;
}

}  // namespace report
