// The fog pass (what the quad, wave and bubble passes apply, in float on the GPU) against the
// fog's closed form in double (fog::sampleAt): 24 small quads facing the camera, 3 to 40 m away
// across the view, each centre pixel against quad colour x transmittance + fog colour, in steps
// of 8-bit colour. The scene is built here through render/, as /v1/render builds it.
#include <glm/geometric.hpp>

#include "fog_common.h"
#include "sections.h"

namespace report {

namespace {

namespace rd = effects::render;

struct Variant {
  std::string name;
  json request;  // the scene's "fog" as a client sends it
  fg::Fog fog;   // the same, as the fog's parser reads it
};

std::vector<Variant> variants() {
  fg::Directional sun;
  sun.color = {1.5, 0.8, 0.3}, sun.direction = {0.3, 0.2, -1}, sun.exponent = 6, sun.startDistance = 5;
  const json sunJson = {{"color", {1.5, 0.8, 0.3}}, {"direction", {0.3, 0.2, -1}}, {"exponent", 6}, {"startDistance", 5}};
  std::vector<Variant> out;
  fg::Fog exp2;
  exp2.type = fg::FogType::kGlExp2, exp2.color = {0.6, 0.65, 0.7}, exp2.density = 0.04;
  out.push_back({"GL_EXP2", {{"fogType", "GL_EXP2"}, {"color", {0.6, 0.65, 0.7}}, {"density", 0.04}}, exp2});
  fg::Fog height;
  height.type = fg::FogType::kHeight, height.color = {0.55, 0.6, 0.7}, height.density = 0.06, height.heightFalloff = 0.3;
  const json heightJson = {{"fogType", "HEIGHT"}, {"color", {0.55, 0.6, 0.7}}, {"density", 0.06}, {"heightFalloff", 0.3}};
  out.push_back({"HEIGHT", heightJson, height});
  fg::Fog terms = height;
  terms.startDistance = 4, terms.maxOpacity = 0.9, terms.secondLayer = fg::HeightLayer{0.03, 0.1, 2}, terms.directional = sun;
  json termsJson = heightJson;
  termsJson.update({{"startDistance", 4},
                    {"maxOpacity", 0.9},
                    {"secondLayer", {{"density", 0.03}, {"heightFalloff", 0.1}, {"baseHeight", 2}}},
                    {"directional", sunJson}});
  out.push_back({"HEIGHT + engine terms + sun", termsJson, terms});
  fg::Fog filament = height;
  filament.convention = fg::Convention::kFilament, filament.startDistance = 4, filament.maxOpacity = 0.9, filament.directional = sun;
  json filamentJson = heightJson;
  filamentJson.update({{"convention", "filament"}, {"startDistance", 4}, {"maxOpacity", 0.9}, {"directional", sunJson}});
  out.push_back({"HEIGHT, filament convention + sun", filamentJson, filament});
  fg::Fog atmospheric;
  atmospheric.type = fg::FogType::kAtmospheric, atmospheric.color = {0.9, 0.7, 0.5};
  atmospheric.extinction = {0.02, 0.05, 0.09}, atmospheric.inscattering = {0.01, 0.04, 0.08};
  out.push_back({"ATMOSPHERIC",
                 {{"fogType", "ATMOSPHERIC"},
                  {"color", {0.9, 0.7, 0.5}},
                  {"extinction", {0.02, 0.05, 0.09}},
                  {"inscattering", {0.01, 0.04, 0.08}}},
                 atmospheric});
  return out;
}

struct Probe {
  rd::Scene scene;
  std::vector<glm::dvec3> points;
  std::vector<std::pair<int, int>> pixels;
};

Probe probeOf(bool quick, const fg::Fog& fog) {
  const int w = quick ? 128 : 512, h = w / 2;
  const double aspect = double(w) / h, tanHalf = std::tan(30.0 * kPi / 180), cameraY = 2;
  Probe p;
  p.scene.width = w, p.scene.height = h;
  p.scene.camera.position = {0, cameraY, 0};
  p.scene.camera.target = {0, cameraY, -1};
  p.scene.camera.fovYDeg = 60;
  p.scene.background.color = {0, 0, 0, 1};
  p.scene.fog = rd::Fog{fog, {}};
  for (int row = 0; row < 4; ++row)
    for (int col = 0; col < 6; ++col) {
      const double ndcX = -0.8 + 1.6 * col / 5, ndcY = -0.6 + 1.2 * row / 3;
      const double d = 3 + 37.0 * (row * 6 + col) / 23;
      const glm::dvec3 dir = glm::normalize(glm::dvec3(ndcX * tanHalf * aspect, ndcY * tanHalf, -1));
      const glm::dvec3 c = glm::dvec3(0, cameraY, 0) + dir * d;
      rd::Quad q;
      q.center = c, q.normal = -dir, q.size = {0.06 * d, 0.06 * d}, q.color = {0.9, 0.6, 0.2};
      p.scene.quads.push_back(q);
      p.points.push_back(c);
      p.pixels.emplace_back(int(std::floor((ndcX * 0.5 + 0.5) * w)), int(std::floor((0.5 - ndcY * 0.5) * h)));
    }
  return p;
}

void measure(Run& run) {
  for (const Variant& v : variants()) {
    Row r;
    r.series = v.name;
    r.setting = "GPU, float";
    r.group = v.name;
    r.request = {{"fog", {{"fog", v.request}}}};
    r.ticket = timeFrames(run, "render fog " + v.name, [quick = run.quick, fog = v.fog] { return probeOf(quick, fog).scene; },
                          run.quick ? 2 : 7);
    run.rows.push_back(r);
  }
}

bool errors(Run& run, rd::Renderer& renderer) {
  const std::vector<Variant> vs = variants();
  for (size_t i = 0; i < vs.size(); ++i) {
    const Probe probe = probeOf(run.quick, vs[i].fog);
    const rd::Scene& scene = probe.scene;
    auto f = renderer.render(scene);
    if (!f.ok()) return std::fprintf(stderr, "error_report: fog %s: %s\n", vs[i].name.c_str(), f.error().message.c_str()), false;
    const std::vector<uint8_t> px = rd::bytes8(f.value().image);
    double worst = 0, sum = 0;
    for (size_t q = 0; q < probe.points.size(); ++q) {
      const fg::Sample s = fg::sampleAt(scene.fog->global, scene.fog->regions, scene.camera.position, probe.points[q]);
      const auto [x, y] = probe.pixels[q];
      for (int c = 0; c < 3; ++c) {
        const double want = std::clamp(scene.quads[q].color[c] * s.transmittance[c] + s.fogColor[c], 0.0, 1.0);
        const double got = px[(size_t(y) * size_t(scene.width) + size_t(x)) * 4 + size_t(c)];
        const double steps = std::abs(got - want * 255);
        worst = std::max(worst, steps), sum += steps;
      }
    }
    run.rows[i].errors["maxSteps"] = worst;
    run.rows[i].note = fmt(sum / double(3 * probe.points.size()), 3);
  }
  return true;
}

std::string conclude(const Section&, const Run& run) {
  return "The fog pass is the closed form in float: every fog here within " + fmt(worstOf(run, "maxSteps"), 2) +
         " steps of 8-bit colour of the double-precision closed form at the quads' centres; its cost is the frame's.";
}

}  // namespace

Section renderFogSection() {
  Section s;
  s.id = "render-fog";
  s.effect = "render";
  s.title = "Render previews: the fog pass against the fog's closed form";
  s.reference =
      "fog::sampleAt in double (the closed forms of docs/effects.md §2), at the centre of 24 quads 3 to 40 m away: quad "
      "colour x transmittance + fog colour";
  s.metrics = {{"maxSteps", "steps", "max abs(pixel − closed form) over the quads, in steps of 8-bit colour", 2.0,
                "2 steps of 8-bit colour, a visible band"}};
  s.timeName = "ms per 512 × 256 frame (median; 128 × 64 in the quick run)";
  s.settingName = "fog";
  s.noteName = "mean steps";
  s.code = {"render", "effects/fog"};
  s.asks = {{"HEIGHT + engine terms + sun", "a 512 × 256 preview in height fog with a sun", {{"width", 512}, {"height", 256}}}};
  s.checkRelative = 0, s.checkAbsolute = 1.01;  // one 8-bit step: llvmpipe rounds differently on another CPU
  s.measure = measure;
  s.afterTiming = errors;
  s.conclude = conclude;
  return s;
}

}  // namespace report
