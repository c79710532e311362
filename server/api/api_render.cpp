// POST /v1/render (scene -> image/png) and POST /v1/scene (scene -> each effect's JSON).
#include <cstdio>
#include <memory>
#include <optional>

#include <effects/bubble.h>

#include "api/api_bubble.h"
#include "api/api_common.h"
#include "api/api_fog.h"
#include "api/api_lightning.h"
#include "api/api_render.h"
#include "api/costs.h"
#include "api/error_estimates.h"
#include "api/movie.h"
#include "api/scene.h"

namespace effectd {

using nlohmann::json;
namespace rd = effects::render;

namespace {

// A scene's part at `at`: the context its endpoint's problems are named in.
RequestContext partContext(const RequestContext& ctx, const std::string& at) {
  RequestContext c = ctx;
  c.at = at;
  return c;
}

JsonReply runScene(const SceneRequest& request, const json& body, const RequestContext& ctx) {
  JsonReply reply;
  reply.method = "scene";
  json out = json::object();
  // One part's answer; its problems name fields under `at`.
  auto answer = [&](JsonReply r, const std::string& at, const char* endpoint) {
    if (!r.binary.empty())  // e.g. bubble "format": "glb"
      throw fieldError(422, at + "/format",
                       "a scene answers JSON: ask /v1/" + std::string(endpoint) + " itself for this binary format");
    reply.computeMs += r.computeMs;
    reply.errorMs += r.errorMs;
    // A part's error header, named by its pointer (the body carries the rest: tables, shading).
    if (const auto e = r.headers.find("X-Effect-Error"); e != r.headers.end()) {
      std::string& all = reply.headers["X-Effect-Error"];
      all += (all.empty() ? "" : ", ") + ("part=" + at + "; " + e->second);
    }
    return std::move(r.body);
  };
  if (request.lightning)
    out["lightning"] = answer(runLightning(*request.lightning, body["lightning"], partContext(ctx, "/lightning")),
                              "/lightning", "lightning");
  if (request.fog) out["fog"] = answer(runFog(*request.fog, body["fog"], partContext(ctx, "/fog")), "/fog", "fog");
  if (body.contains("bubbles")) out["bubbles"] = json::array();
  for (const SceneBubble& b : request.bubbles) {
    json part = answer(runBubble(b.request, body[json::json_pointer(b.at)], partContext(ctx, b.at)), b.at, "bubble");
    if (b.at == "/bubble")
      out["bubble"] = std::move(part);
    else
      out["bubbles"].push_back(std::move(part));
  }
  reply.body = std::move(out);
  return reply;
}

// The bubble ray traced on the CPU (render::referenceRender), a still of at most
// kMaxReferencePixels: the answer of `reference: true` and what `measureError` compares with.
rd::Reference traceReference(const RenderRequest& request, const rd::Scene& scene, const json& body,
                             const RequestContext& ctx) {
  if (request.frames) throw fieldError(422, "/frames", "the reference is a still: leave frames out");
  const size_t pixels = size_t(request.width) * size_t(request.height);
  if (pixels > kMaxReferencePixels)
    throw fieldError(413, "/width",
                     "the reference traces " + std::to_string(rd::kReferenceWavelengths) +
                         " wavelengths per pixel: at most " + std::to_string(kMaxReferencePixels) + " pixels");
  auto r = rd::referenceRender(scene, ctx.parallel);
  // Its one bubble, which may be the first of "bubbles" (none: the missing "/bubble").
  const std::string at = request.scene.bubbles.empty() ? "/bubble" : request.scene.bubbles.front().at;
  if (!r.ok()) throwError(r.error(), "", {{"bubble", {at}}});
  return std::move(r.value());
}

// X-Effect-Error of a frame measured against the reference: CIE76 Delta E*ab per pixel where the
// reference's ray meets the bubble (the frame as its 8-bit PNG holds it).
std::string frameError(const rd::Image& frame, const rd::Reference& ref) {
  const std::vector<double> de = rd::bubbleDeltaE(frame, ref);
  double sum = 0, worst = 0;
  for (double d : de) sum += d, worst = std::max(worst, d);
  char out[256];
  std::snprintf(out, sizeof out,
                "pass=bubble; meanDeltaE=%.4g; maxDeltaE=%.4g; pixels=%zu; limit=%g; kind=measured; "
                "reference=\"CPU ray tracing, %d wavelengths\"",
                de.empty() ? 0.0 : sum / double(de.size()), worst, de.size(),
                reported("render-bubble", "", "", "meanDeltaE").limit, rd::kReferenceWavelengths);
  return out;
}

// X-Effect-Error's entries for what a frame draws besides a measured bubble: each bubble's
// shading estimate, the fog's and the bolt's figures, all as the error report and the render
// tests hold them (docs/rendering.md).
std::vector<std::string> passEstimates(const rd::Scene& scene, bool bubbleMeasured) {
  std::vector<std::string> out;
  char e[320];
  if (!bubbleMeasured)
    for (const rd::Bubble& b : scene.bubbles) {
      const ErrorEstimate s = shadingErrorEstimate(b.features);
      std::snprintf(e, sizeof e,
                    "pass=bubble; meanDeltaE=%.3g; limit=%g; kind=estimate; variant=\"%s\"; "
                    "reference=\"CPU ray tracing, %d wavelengths, on the error report's scene\"",
                    s.value, s.limit, s.row.c_str(), rd::kReferenceWavelengths);
      out.push_back(e);
    }
  if (scene.fog) {
    const ErrorEstimate f = fogPassErrorEstimate();
    std::snprintf(e, sizeof e,
                  "pass=fog; maxSteps8bit=%.3g; limit=%g; kind=estimate; reference=\"the fog's closed form in double "
                  "(fog::sampleAt), the worst of the error report's fogs\"",
                  f.value, f.limit);
    out.push_back(e);
  }
  if (scene.lightning) {
    const ErrorEstimate l = lightningPassErrorEstimate();
    std::snprintf(e, sizeof e,
                  "pass=lightning; maxOffsetPx=%g; limit=%g; kind=bound; reference=\"the answer's own polyline: the "
                  "main channel's pixels lie within lightningStyle.coreWidth + %g px of it (the glow spreads by "
                  "design)\"",
                  l.limit, l.limit, l.limit);
    out.push_back(e);
  }
  return out;
}

JsonReply referenceReply(const RenderRequest& request, const json& body, const RequestContext& ctx) {
  JsonReply reply;
  reply.method = "reference";
  rd::Scene scene = buildScene(request, body, ctx, &reply.computeMs);
  auto r = traceReference(request, scene, body, ctx);
  auto png = rd::encodePng(r.image, scene.bitDepth, ctx.parallel);
  if (!png.ok()) throwError(png.error());
  reply.binary = std::move(png.value());
  reply.contentType = "image/png";
  reply.computeMs += r.ms;
  reply.headers = {
      {"X-Renderer", "reference: CPU ray tracing, " + std::to_string(rd::kReferenceWavelengths) + " wavelengths"}};
  return reply;
}

}  // namespace

// Each part read by its endpoint's parser at its pointer; a bubble's lights are the scene's
// when it has them, as the render lights it.
SceneRequest parseSceneRequest(const json& body, const RequestContext& ctx) {
  SceneRequest r;
  if (body.contains("lightning"))
    r.lightning = parseLightningRequest(body["lightning"], partContext(ctx, "/lightning"));
  if (body.contains("fog")) r.fog = parseFogRequest(body["fog"], partContext(ctx, "/fog"));
  auto add = [&](const std::string& at, const std::string& styleAt) {
    json lit = body[json::json_pointer(at)];
    if (body.contains("lights")) lit["lights"] = body["lights"];
    r.bubbles.push_back({parseBubbleRequest(lit, partContext(ctx, at)), at, styleAt});
  };
  if (body.contains("bubble")) add("/bubble", "/bubbleStyle");
  if (body.contains("bubbles"))
    for (size_t i = 0; i < body["bubbles"].size(); ++i)
      add("/bubbles/" + std::to_string(i) + "/bubble", "/bubbles/" + std::to_string(i));
  return r;
}

RenderRequest parseRenderRequest(const json& body, const RequestContext& ctx) {
  RenderRequest r;
  r.scene = parseSceneRequest(body, ctx);
  r.reference = body.value("reference", r.reference);
  r.measureError = body.value("measureError", r.measureError);
  const rd::Scene defaults;
  r.width = body.value("width", defaults.width);
  r.height = body.value("height", defaults.height);
  if (body.contains("frames")) r.frames = body["frames"]["count"].get<int>();
  r.backgroundImage = body.contains("background") && body["background"].contains("image");
  return r;
}

void addRenderEndpoints(Service& service) {
  const Config& config = service.config();
  auto pool =
      std::make_shared<rd::RenderPool>(rd::PoolOptions{config.renderThreads, config.renderQueue, config.eglPlatform});
  service.addReadinessCheck("renderer", [pool] { return pool->start(); });
  service.addReadinessInfo("renderer", [pool] { return pool->description(); });
  service.addJsonEndpoint("/v1/scene", "scene.json", twoSteps(parseSceneRequest, sceneCost, runScene));
  Metrics* metrics = &service.metrics();
  auto run = [pool, metrics](const RenderRequest& request, const json& body, const RequestContext& ctx) {
    if (request.reference) return referenceReply(request, body, ctx);
    JsonReply reply;
    reply.method = "render";
    Animation animation;
    rd::Scene scene = buildScene(request, body, ctx, &reply.computeMs, &animation);
    std::vector<std::string> estimates = passEstimates(scene, request.measureError);
    std::optional<rd::Reference> reference;  // measureError: traced first, so that a scene it cannot
    effects::Stopwatch measuring;            // trace is refused before the GPU works
    if (request.measureError) reference = traceReference(request, scene, body, ctx);
    const double referenceMs = measuring.ms();
    auto drawn =
        renderScene(std::move(scene), animation, ctx.parallel, [&pool](rd::Scene s, const rd::Sequence* sequence) {
          auto job = sequence ? pool->submit(std::move(s), *sequence) : pool->submit(std::move(s));
          if (!job)
            throw ApiError{503,
                           "render-queue-full",
                           "Render queue full",
                           "every render thread is busy and the queue is full; retry shortly (--render-queue)",
                           {},
                           {{"Retry-After", "1"}}};
          return job->get();
        });
    if (!drawn.ok()) throwError(drawn.error());
    const rd::Frame& f = drawn.value().frame;
    reply.headers = {{"X-Renderer", pool->description()}, {"X-Render-Passes", f.passList()}};
    if (!f.glow.empty()) reply.headers["X-Glow"] = f.glow;
    reply.binary = std::move(drawn.value().output.bytes);
    reply.contentType = drawn.value().output.contentType;
    for (auto& [name, value] : drawn.value().output.headers) reply.headers[name] = std::move(value);
    for (const auto& p : f.passes) metrics->count("render_passes", p);
    metrics->count("shader_variants_compiled", "render", f.variantsCompiled);
    const double encodeMs = drawn.value().encodeMs;
    reply.stages = {
        {"scene", reply.computeMs}, {"queue", f.queueMs}, {"draw", f.drawMs}, {"read", f.readMs}, {"encode", encodeMs}};
    reply.computeMs += f.ms + encodeMs;
    reply.runHeaders = {{"X-Shader-Variants-Compiled", std::to_string(f.variantsCompiled)},
                        {"X-Render-Ms", std::to_string(f.ms)}};
    if (reference) {
      effects::Stopwatch comparing;
      estimates.insert(estimates.begin(), frameError(f.image, *reference));
      reply.errorMs = referenceMs + comparing.ms();
    }
    std::string error;
    for (const std::string& e : estimates) error += (error.empty() ? "" : ", ") + e;
    if (!error.empty()) reply.headers["X-Effect-Error"] = error;
    return reply;
  };
  service.addJsonEndpoint("/v1/render", "scene.json", twoSteps(parseRenderRequest, renderCost, run));
  // The same scene renders alike on the same renderer: it is part of the render's ETag.
  service.setEtagSalt("/v1/render", [pool] { return pool->start().empty() ? pool->description() : std::string(); });
}

}  // namespace effectd
