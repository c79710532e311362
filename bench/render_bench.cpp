// 512x512 render latency on whatever EGL offers (llvmpipe without a GPU), p50 and p99, for
// lightning only, fog only, bubble only and all three, then the bubble's shading variants (the
// paper's model, + its film table; the film front only, + the far side, + highlights). Columns:
// the frame itself (GPU passes + read-back, variants already compiled), the whole request path
// (scene building with the server's thread pool: bolt growth, icosphere, thin-film table, film
// thickness; the frame; PNG encoding), then the p50 of each stage: build, draw (the passes
// issued and finished), read (read-back into the PNG's format), png (encoding).
//   build/bench/render_bench [iterations=40]
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <vector>

#include <render/render.h>

#include "contract/config.h"
#include "api/api_render.h"
#include "api/scene.h"

namespace {

using nlohmann::json;
namespace rd = effects::render;

const json kLightning = {
    {"grid", {{"width", 128}, {"height", 128}}}, {"start", {64, 0}}, {"targets", {{64, 127}}}, {"seed", 7}};
const json kFog = {
    {"fog", {{"fogType", "HEIGHT"}, {"color", {0.5, 0.55, 0.6}}, {"density", 0.08}, {"heightFalloff", 0.5}}}};
const json kBubble = {{"mesh", {{"level", 4}}}};
const json kQuads = {{{"center", {0, -1, -10}}, {"normal", {0, 1, 0}}, {"up", {0, 0, -1}}, {"size", {40, 30}}},
                     {{"center", {-3, 0.5, -6}}, {"size", {1.5, 3}}}};

json scene(bool lightning, bool fog, bool bubble) {
  json s = {{"width", 512},
            {"height", 512},
            {"background", {{"gradient", {{"top", {0.1, 0.1, 0.2}}, {"bottom", {0.4, 0.4, 0.5}}}}}}};
  if (lightning) s["lightning"] = kLightning;
  if (fog) s["fog"] = kFog, s["quads"] = kQuads;
  if (bubble) s["bubble"] = kBubble;
  return s;
}

double percentile(std::vector<double> v, double p) {
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
}

// Renders `body` iterations + 1 times as a request would (the first, which compiles the
// variants, not counted) and prints one row: frame and request p50/p99, then the p50 of each
// stage of the request (scene building, the passes drawn and finished, the read-back, the PNG);
// false when the renderer refuses.
bool measure(rd::Renderer& renderer, const effectd::RequestContext& ctx, const char* name, const json& body,
             int iterations) {
  std::vector<double> frame, request, build, draw, read, png;
  std::string passes;
  for (int i = 0; i <= iterations; ++i) {
    effects::Stopwatch watch;
    rd::Scene s = effectd::buildScene(effectd::parseRenderRequest(body, ctx), body, ctx);
    const double built = watch.ms();
    auto f = renderer.render(s);
    if (!f.ok()) {
      std::fprintf(stderr, "%s: %s\n", name, f.error().message.c_str());
      return false;
    }
    effects::Stopwatch encode;
    auto bytes = rd::encodePng(f.value().image, 8, ctx.parallel);
    if (i == 0) {
      passes = f.value().passList();
      continue;
    }
    frame.push_back(f.value().ms);
    request.push_back(watch.ms());
    build.push_back(built);
    draw.push_back(f.value().drawMs);
    read.push_back(f.value().readMs);
    png.push_back(encode.ms());
  }
  std::printf("%-16s %9.1f ms %9.1f ms %11.1f ms %11.1f ms  %6.1f %6.1f %6.1f %6.1f  %s\n", name,
              percentile(frame, 0.5), percentile(frame, 0.99), percentile(request, 0.5), percentile(request, 0.99),
              percentile(build, 0.5), percentile(draw, 0.5), percentile(read, 0.5), percentile(png, 0.5),
              passes.c_str());
  return true;
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::max(2, std::atoi(argv[1])) : 40;
  effectd::Config config;
  // As the server builds scenes: the request's thread and a pool of the other cores.
  effects::ThreadPool pool(effects::ThreadPool::besideCaller());
  const effectd::RequestContext ctx{"bench", config, &pool};
  auto renderer = rd::Renderer::create();
  if (!renderer.ok()) {
    std::fprintf(stderr, "render_bench: %s\n", renderer.error().message.c_str());
    return 1;
  }
  std::printf("renderer: %s, 512x512, %d iterations each\n\n", renderer.value()->description().c_str(), iterations);
  std::printf("%-16s %12s %12s %14s %14s  %6s %6s %6s %6s  %s\n", "scene", "frame p50", "frame p99", "request p50",
              "request p99", "build", "draw", "read", "png", "passes");
  struct Case {
    const char* name;
    bool lightning, fog, bubble;
  };
  for (const Case& c : {Case{"lightning only", true, false, false}, Case{"fog only", false, true, false},
                        Case{"bubble only", false, false, true}, Case{"all three", true, true, true}}) {
    if (!measure(*renderer.value(), ctx, c.name, scene(c.lightning, c.fog, c.bubble), iterations)) return 1;
  }
  // The bubble's shading variants alone, each building its scene as a request does; the film's
  // frames include its thickness texture (128 x 64 by default), recomputed each frame.
  struct Variant {
    const char* name;
    json bubble;
  };
  const json film = {{"mesh", {{"level", 4}}}};
  auto with = [&](json b, const json& extra) {
    b.update(extra);
    return b;
  };
  for (const Variant& v :
       {Variant{"paper", with(film, {{"shading", "paper"}})},
        Variant{"paper+table", with(film, {{"shading", "paper"}, {"features", {{"iridescence", true}}}})},
        Variant{"film front", with(film, {{"features", {{"backFace", false}, {"highlight", false}}}})},
        Variant{"film +back", with(film, {{"features", {{"highlight", false}}}})},
        Variant{"film +highlight", film}}) {
    json body = scene(false, false, false);
    body["bubble"] = v.bubble;
    if (!measure(*renderer.value(), ctx, v.name, body, iterations)) return 1;
  }
  std::printf("\ntarget: all three, request p50 <= 150 ms on the 2-core CI-class machine\n");
  return 0;
}
