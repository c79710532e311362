// POST /v1/render (scene -> image/png) and POST /v1/scene (scene -> each effect's JSON).
#include <memory>

#include "api_bubble.h"
#include "api_common.h"
#include "api_fog.h"
#include "api_lightning.h"
#include "api_render.h"
#include "costs.h"
#include "movie.h"
#include "scene.h"

namespace effectd {

using nlohmann::json;
namespace rd = effects::render;

namespace {

JsonReply handleScene(const json& body, const RequestContext& ctx) {
  JsonReply reply;
  reply.method = "scene";
  json out = json::object();
  // One part's answer; its problems name fields under `at`.
  auto answer = [&](const json& part, const std::string& at, const char* endpoint,
                    JsonReply (*handler)(const json&, const RequestContext&)) {
    RequestContext c = ctx;
    c.at = at;
    JsonReply r = handler(part, c);
    if (!r.binary.empty())  // e.g. bubble "format": "glb"
      throw fieldError(422, at + "/format",
                       "a scene answers JSON: ask /v1/" + std::string(endpoint) + " itself for this binary format");
    reply.computeMs += r.computeMs;
    return std::move(r.body);
  };
  auto add = [&](const char* name, JsonReply (*handler)(const json&, const RequestContext&)) {
    if (body.contains(name)) out[name] = answer(body[name], std::string("/") + name, name, handler);
  };
  add("lightning", handleLightning);
  add("fog", handleFog);
  // A bubble's uniforms as the render lights it: the scene's lights first.
  auto lit = [&](json bubble) {
    if (body.contains("lights")) bubble["lights"] = body["lights"];
    return bubble;
  };
  if (body.contains("bubble")) out["bubble"] = answer(lit(body["bubble"]), "/bubble", "bubble", handleBubble);
  if (body.contains("bubbles")) {
    out["bubbles"] = json::array();
    for (size_t i = 0; i < body["bubbles"].size(); ++i)
      out["bubbles"].push_back(answer(lit(body["bubbles"][i]["bubble"]), "/bubbles/" + std::to_string(i) + "/bubble",
                                      "bubble", handleBubble));
  }
  reply.body = std::move(out);
  return reply;
}

// `reference: true`: the bubble ray traced on the CPU (render::referenceRender), a still of
// at most kMaxReferencePixels.
JsonReply referenceReply(const json& body, const RequestContext& ctx) {
  if (body.contains("frames")) throw fieldError(422, "/frames", "the reference is a still: leave frames out");
  const size_t pixels = size_t(body.value("width", 512)) * size_t(body.value("height", 512));
  if (pixels > kMaxReferencePixels)
    throw fieldError(413, "/width",
                     "the reference traces " + std::to_string(rd::kReferenceWavelengths) +
                         " wavelengths per pixel: at most " + std::to_string(kMaxReferencePixels) + " pixels");
  JsonReply reply;
  reply.method = "reference";
  rd::Scene scene = buildScene(body, ctx, &reply.computeMs);
  auto r = rd::referenceRender(scene, ctx.parallel);
  if (!r.ok()) {
    effects::Error e = r.error();  // its one bubble may be the first of "bubbles"
    if (!body.contains("bubble") && e.field.rfind("/bubble/", 0) == 0) e.field = "/bubbles/0" + e.field;
    throwError(e);
  }
  auto png = rd::encodePng(r.value().image, scene.bitDepth, ctx.parallel);
  if (!png.ok()) throwError(png.error());
  reply.binary = std::move(png.value());
  reply.contentType = "image/png";
  reply.computeMs += r.value().ms;
  reply.headers = {{"X-Renderer", "reference: CPU ray tracing, " + std::to_string(rd::kReferenceWavelengths) +
                                      " wavelengths"}};
  return reply;
}

}  // namespace

void addRenderEndpoints(Service& service) {
  const Config& config = service.config();
  auto pool =
      std::make_shared<rd::RenderPool>(rd::PoolOptions{config.renderThreads, config.renderQueue, config.eglPlatform});
  service.addReadinessCheck("renderer", [pool] { return pool->start(); });
  service.addReadinessInfo("renderer", [pool] { return pool->description(); });
  service.addJsonEndpoint("/v1/scene", "scene.json", handleScene, sceneCost);
  Metrics* metrics = &service.metrics();
  service.addJsonEndpoint(
      "/v1/render", "scene.json",
      [pool, metrics](const json& body, const RequestContext& ctx) {
        if (body.value("reference", false)) return referenceReply(body, ctx);
        JsonReply reply;
        reply.method = "render";
        Animation animation;
        rd::Scene scene = buildScene(body, ctx, &reply.computeMs, &animation);
        auto drawn = renderScene(std::move(scene), animation, ctx.parallel,
                                 [&pool](rd::Scene s, const rd::Sequence* sequence) {
                                   auto job = sequence ? pool->submit(std::move(s), *sequence) : pool->submit(std::move(s));
                                   if (!job)
                                     throw ApiError{503,
                                                    "render-queue-full",
                                                    "Render queue full",
                                                    "every render thread is busy and the queue is full; retry shortly "
                                                    "(--render-queue)",
                                                    {},
                                                    {{"Retry-After", "1"}}};
                                   return job->get();
                                 });
        if (!drawn.ok()) throwError(drawn.error());
        const rd::Frame& f = drawn.value().frame;
        reply.headers = {{"X-Renderer", pool->description()}, {"X-Render-Passes", f.passList()}};
        reply.binary = std::move(drawn.value().output.bytes);
        reply.contentType = drawn.value().output.contentType;
        for (auto& [name, value] : drawn.value().output.headers) reply.headers[name] = std::move(value);
        for (const auto& p : f.passes) metrics->count("render_passes", p);
        metrics->count("shader_variants_compiled", "render", f.variantsCompiled);
        const double encodeMs = drawn.value().encodeMs;
        reply.stages = {{"scene", reply.computeMs}, {"queue", f.queueMs}, {"draw", f.drawMs},
                        {"read", f.readMs},         {"encode", encodeMs}};
        reply.computeMs += f.ms + encodeMs;
        reply.runHeaders = {{"X-Shader-Variants-Compiled", std::to_string(f.variantsCompiled)},
                            {"X-Render-Ms", std::to_string(f.ms)}};
        return reply;
      },
      renderCost);
  // The same scene renders alike on the same renderer: it is part of the render's ETag.
  service.setEtagSalt("/v1/render", [pool] { return pool->start().empty() ? pool->description() : std::string(); });
}

}  // namespace effectd
