// POST /v1/lightning — grid + obstacles + start/targets -> bolt tree, polylines, quality.
#include <algorithm>
#include <optional>

#include <effects/lightning.h>
#include <render/render.h>

#include "api/api_common.h"
#include "api/api_lightning.h"
#include "api/bolt_ribbons.h"
#include "api/costs.h"
#include "api/error_estimates.h"
#include "contract/codec.h"

namespace effectd {
namespace {

using nlohmann::json;
namespace lt = effects::lightning;

// A cell of the request: [x, y] on a 2-D grid, [x, y, z] on a 3-D one.
lt::Cell cellOf(const json& j, int depth, const std::string& at) {
  if (j.size() != (depth ? 3u : 2u))
    throw fieldError(400, at,
                     depth ? "must be [x, y, z] on a 3-D grid" : "must be [x, y] on a 2-D grid (no grid.depth)");
  return {j[0].get<int>(), j[1].get<int>(), depth ? j[2].get<int>() : 0};
}

// "polylines": per line its channel, width, flat [x, y, ...] points (3-D: [x, y, z, ...], in
// world units with "world"), and per point the step and intensity.
json polylinesJson(const std::vector<lt::Polyline>& polylines, int depth, const World& world) {
  json lines = json::array();
  for (const auto& l : polylines) {
    json xy = json::array(), step = json::array(), intensity = json::array();
    for (const auto& v : l.vertices) {
      if (depth) {
        const auto p = world.toWorld(v.x, v.y, v.z);
        for (double c : p) xy.push_back(wire(c));
      } else {
        xy.push_back(v.x);
        xy.push_back(v.y);
      }
      step.push_back(v.step);
      intensity.push_back(v.intensity);
    }
    lines.push_back({{"channel", l.main ? "main" : "branch"},
                     {"width", world.given ? wire(l.width * world.cellSize) : double(l.width)},
                     {"points", std::move(xy)},
                     {"step", std::move(step)},
                     {"intensity", std::move(intensity)}});
  }
  return lines;
}

// "cells": the bolt's cells in growth order, flat [x, y, ...].
json cellsJson(const lt::Bolt& bolt) {
  json c = json::array();
  for (const auto& n : bolt.nodes) {
    c.push_back(n.cell.x);
    c.push_back(n.cell.y);
    if (bolt.depth) c.push_back(n.cell.z);
  }
  return c;
}

// "tree": each node's parent and step, and the main channel's nodes.
json treeJson(const lt::Bolt& bolt) {
  json parent = json::array(), step = json::array();
  for (const auto& n : bolt.nodes) {
    parent.push_back(n.parent);
    step.push_back(n.step);
  }
  return {{"parent", std::move(parent)}, {"step", std::move(step)}, {"mainChannel", bolt.mainChannel}};
}

// "guide": the A* waypoints, [[x, y], ...].
json guideJson(const lt::Bolt& bolt) {
  json g = json::array();
  for (const auto& c : bolt.guide) g.push_back(bolt.depth ? json::array({c.x, c.y, c.z}) : json::array({c.x, c.y}));
  return g;
}

// The strike without its per-vertex times: connect, duration, strokes and the channels' keyframes.
json strikeJson(const lt::Timeline& tl) {
  json strokes = json::array();
  for (const auto& s : tl.strokes) strokes.push_back({{"t", s.t}, {"peak", s.peak}});
  json t = json::array(), leader = json::array(), main = json::array(), branches = json::array();
  for (const auto& k : tl.keyframes) {
    t.push_back(k.t);
    leader.push_back(k.leader);
    main.push_back(k.main);
    branches.push_back(k.branches);
  }
  return {{"connect", tl.connect},
          {"duration", tl.duration},
          {"strokes", std::move(strokes)},
          {"keyframes",
           {{"t", std::move(t)},
            {"leader", std::move(leader)},
            {"main", std::move(main)},
            {"branches", std::move(branches)}}}};
}

// "timeline": the strike and, per polyline, when each vertex lights.
json timelineJson(const lt::Timeline& tl) {
  json lines = json::array();
  for (size_t i = 0; i < tl.leader.size(); ++i)
    lines.push_back({{"leader", tl.leader[i]}, {"strokeDelay", tl.strokeDelay[i]}});
  json out = strikeJson(tl);
  out["polylines"] = std::move(lines);
  return out;
}

// The strike's physics: top-level animationSeed (default: seed) and timeScale, "timeline".
lt::TimelineParams parseTimeline(const json& body, uint64_t seed, const std::string& at) {
  lt::TimelineParams t;
  t.seed = body.value("animationSeed", seed);
  t.timeScale = body.value("timeScale", t.timeScale);
  const json o = body.value("timeline", json::object());
  t.cellSize = o.value("cellSize", t.cellSize);
  t.leaderStep = o.value("leaderStep", t.leaderStep);
  if (o.contains("leaderPause")) t.pauseMinUs = o["leaderPause"][0], t.pauseMaxUs = o["leaderPause"][1];
  t.returnStrokeSpeed = o.value("returnStrokeSpeed", t.returnStrokeSpeed);
  t.strokes = o.value("strokes", t.strokes);
  if (o.contains("strokeInterval")) t.intervalMinMs = o["strokeInterval"][0], t.intervalMaxMs = o["strokeInterval"][1];
  t.flashMs = o.value("flashDecay", t.flashMs);
  t.glowMs = o.value("glowDecay", t.glowMs);
  t.leaderBrightness = o.value("leaderBrightness", t.leaderBrightness);
  t.flicker = o.value("flicker", t.flicker);
  if (auto e = lt::validate(t)) throwError(*e, at);
  return t;
}

}  // namespace

LightningRequest parseLightningRequest(const json& body, const RequestContext& ctx) {
  const Config& config = ctx.config;
  const std::string& at = ctx.at;
  LightningRequest r;
  lt::Params& p = r.params;
  p.width = body["grid"]["width"];
  p.height = body["grid"]["height"];
  p.depth = body["grid"].value("depth", 0);
  p.method = lt::parseMethod(body.value("method", "fast")).value_or(lt::Method::kFast);  // the schema's enum
  lt::Limits limits;
  limits.maxGridCells = config.limits.maxGridCells, limits.gridKnob = "--max-grid-cells";
  limits.maxSolverGridCells = config.limits.maxSolverGridCells, limits.solverGridKnob = config.limits.solverGridKnob;
  limits.maxSolverVolumeCells = config.limits.maxSolverVolumeCells, limits.solverVolumeKnob = config.limits.solverVolumeKnob;
  if (auto e = lt::checkLimits(p, limits)) {
    // Past a solver bound on a synchronous route, a grid within the job bound may go as a job.
    const size_t cells = size_t(p.width) * size_t(p.height) * size_t(std::max(p.depth, 1));
    const size_t job = p.depth ? config.maxJobVolumeCells : config.maxJobGridCells;
    if (config.limits.jobsTakeMore && p.method != lt::Method::kFast && cells <= limits.maxGridCells && cells <= job)
      e->message += "; send it as a job: POST /v1/jobs or Prefer: respond-async (jobs take up to " +
                    std::to_string(job) + " cells, " + (p.depth ? "--max-job-volume-cells" : "--max-job-grid-cells") + ")";
    throwError(*e, at);
  }
  if (body.contains("world") && !p.depth) throw fieldError(400, at + "/world", "is for 3-D grids (grid.depth)");
  r.world = parseWorld(body);
  p.start = cellOf(body["start"], p.depth, at + "/start");
  p.targets.clear();
  for (size_t i = 0; i < body.value("targets", json::array()).size(); ++i)
    p.targets.push_back(cellOf(body["targets"][i], p.depth, at + "/targets/" + std::to_string(i)));
  p.eta = body.value("eta", p.eta);
  p.neighbourhood = body.value("neighbourhood", lt::defaultNeighbourhood(p.depth));
  p.solver = lt::parseSolver(body.value("solver", "capacitance")).value_or(lt::Solver::kCapacitance);  // the schema's enums
  p.tolerance = body.value("tolerance", p.tolerance);
  p.guide = lt::parseGuide(body.value("guide", "auto")).value_or(lt::Guide::kAuto);
  p.seed = body.value("seed", uint64_t(1));
  p.maxSteps = std::min<size_t>(body.value("maxSteps", config.limits.maxGrowthSteps), config.limits.maxGrowthSteps);
  lt::ShapeParams& shape = r.shape;
  const json s = body.value("shape", json::object());
  shape.jitter = s.value("jitter", shape.jitter);
  shape.jitterSeed = s.value("jitterSeed", p.seed);
  shape.branchWidth = s.value("branchWidth", shape.branchWidth);
  shape.branchIntensity = s.value("branchIntensity", shape.branchIntensity);
  shape.branchFalloff = s.value("branchFalloff", shape.branchFalloff);
  r.timeline = parseTimeline(body, p.seed, at);
  r.include = Includes(body, kLightningIncludes);
  r.glb = body.value("format", "json") == "glb";
  r.variant = body.value("variant", r.variant);
  if (body.contains("lifetime")) r.lifetime = body["lifetime"].get<int>();
  if (body.contains("axisGrowth")) r.axisGrowth = body["axisGrowth"].get<double>();
  if (body.contains("obstacles"))
    r.obstacles = parseCellShapes(body["obstacles"], p.width, p.height, p.depth, r.world, config, at + "/obstacles");
  if (body.contains("targetRegion")) {
    r.targetRegion =
        parseCellShapes(body["targetRegion"], p.width, p.height, p.depth, r.world, config, at + "/targetRegion");
    if (!r.targetRegion.given) throw fieldError(400, at + "/targetRegion", "holds no cell of the grid");
  }
  return r;
}

lt::Params boltParams(const LightningRequest& r, const std::string& at) {
  lt::Params p = r.params;
  p.obstacles = drawCellShapes(r.obstacles, p.width, p.height, p.depth);  // a mesh is voxelised here
  if (r.targetRegion.given) {
    p.targetRegion = drawCellShapes(r.targetRegion, p.width, p.height, p.depth);
    if (std::find(p.targetRegion.begin(), p.targetRegion.end(), uint8_t(1)) == p.targetRegion.end())
      throw fieldError(400, at + "/targetRegion", "holds no cell of the grid");
  }
  lt::calibrate(p);            // from one look at the obstacles
  if (r.variant == "paper") lt::usePaperConstants(p);
  p.lifetime = r.lifetime.value_or(p.lifetime);
  p.axisGrowth = r.axisGrowth.value_or(p.axisGrowth);
  return p;
}

lt::Bolt growBolt(lt::Params p, const std::string& at, const JobProgress& progress) {
  if (progress) p.progress = [&progress](const lt::Progress& g) { return progress(g.fraction, g.cells, g.steps); };
  auto grown = lt::grow(p);
  if (!grown.ok())
    throwError(grown.error(), at, {{"maxSteps", {at + "/maxSteps", 1, "--max-growth-steps / maxSteps"}}});
  return std::move(grown.value());
}


namespace {

// X-Effect-Error: the bolt's mean TV distance per step from DBM's converged distribution,
// measured (include "error") or the error report's figure for the method.
std::string errorHeader(const lt::Params& p, const lt::Bolt& bolt) {
  char out[320];
  const ErrorEstimate e = lightningErrorEstimate(p);  // its limit of use applies to a measured figure too
  if (p.measureError) {
    std::snprintf(out, sizeof out, "meanTotalVariation=%.4g; limit=%g; kind=measured; reference=\"%s\"",
                  bolt.stats.error.value_or(0.0), e.limit, bolt.stats.reference.c_str());
  } else {
    std::snprintf(out, sizeof out,
                  "meanTotalVariation=%.3g; limit=%g; kind=estimate; row=\"%s, %s\"; reference=\"DBM's converged "
                  "per-step distribution, in the error report; include error measures this bolt\"",
                  e.value, e.limit, e.row.c_str(), e.setting.c_str());
  }
  return out;
}

}  // namespace

JsonReply runLightning(const LightningRequest& request, const json& /*body*/, const RequestContext& ctx) {
  const Includes& include = request.include;
  const bool glbFormat = request.glb;  // include: only timeline applies
  lt::Params p = boltParams(request, ctx.at);
  p.measureError = include.has("error") && !glbFormat;
  p.parallel = ctx.parallel;  // the same bolt on any threads
  const lt::Bolt bolt = growBolt(p, ctx.at, ctx.progress);
  JsonReply reply;
  reply.method = bolt.stats.method;
  reply.computeMs = bolt.stats.elapsedMs;  // the method's own: the reference's solves are errorMs
  reply.errorMs = bolt.stats.errorMs;
  reply.headers["X-Effect-Error"] = errorHeader(p, bolt);
  json out = {{"method", bolt.stats.method},
              {"grid", p.depth ? json::array({p.width, p.height, p.depth}) : json::array({p.width, p.height})}};
  if (request.world.given) out["world"] = {{"origin", request.world.origin}, {"cellSize", request.world.cellSize}};
  if (p.method != lt::Method::kDbm) out["variant"] = request.variant;
  out["mainChannelLength"] = bolt.mainChannel.size();
  out["cellCount"] = bolt.nodes.size();
  out["steps"] = bolt.nodes.back().step;
  if (!p.targetRegion.empty()) {
    const lt::Cell s = bolt.nodes[size_t(bolt.mainChannel.back())].cell;
    out["struck"] = p.depth ? json::array({s.x, s.y, s.z}) : json::array({s.x, s.y});
  }

  if (include.has("polylines") || include.has("timeline") || include.has("mesh") || glbFormat) {
    const std::vector<lt::Polyline> lines = lt::polylines(bolt, request.shape);
    std::optional<lt::Timeline> timeline;
    if (include.has("timeline")) {
      auto strike = lt::timeline(bolt, lines, request.timeline);
      if (!strike.ok()) throwError(strike.error(), ctx.at);
      timeline = std::move(strike.value());
    }
    if (glbFormat) {  // the ribbons as one file instead of JSON; the timeline's times per vertex
      const json strike = timeline ? strikeJson(*timeline) : json(nullptr);
      const auto ribbons = boltRibbons(lines, p.depth, request.world, timeline ? &*timeline : nullptr);
      const glm::dvec3 color = effects::render::Lightning{}.color;  // the preview's
      reply.binary = boltGlb(ribbons, {color.x, color.y, color.z}, strike);
      reply.contentType = "model/gltf-binary";
      return reply;
    }
    if (include.has("polylines")) out["polylines"] = polylinesJson(lines, p.depth, request.world);
    if (include.has("mesh"))
      out["mesh"] = ribbonsJson(boltRibbons(lines, p.depth, request.world, timeline ? &*timeline : nullptr));
    if (timeline) out["timeline"] = timelineJson(*timeline);
  }
  if (include.has("cells")) out["cells"] = cellsJson(bolt);
  if (include.has("tree")) out["tree"] = treeJson(bolt);
  if (include.has("guide")) out["guide"] = guideJson(bolt);
  if (include.has("fractalDimension") || include.has("shape")) {
    const lt::BoltShape shape = lt::shapeOf(bolt, p.width, p.height, p.depth);
    if (include.has("fractalDimension")) out["fractalDimension"] = shape.dimension;
    if (include.has("shape"))
      out["shape"] = {{"cells", size_t(shape.cells)},
                      {"tips", size_t(shape.tips)},
                      {"branchPoints", size_t(shape.branchPoints)},
                      {"fractalDimension", shape.dimension}};
  }
  if (include.has("error")) {
    out["error"] = {{"meanTotalVariation", bolt.stats.error.value_or(0.0)},
                    {"kind", "measured"},
                    {"metric", bolt.stats.errorMetric},
                    {"reference", bolt.stats.reference}};
  }
  if (include.has("stats")) out["stats"] = statsJson(bolt.stats);
  reply.body = std::move(out);
  return reply;
}

JsonReply handleLightning(const json& body, const RequestContext& ctx) {
  return runLightning(parseLightningRequest(body, ctx), body, ctx);
}

void addLightningEndpoints(Service& service) {
  service.addJsonEndpoint("/v1/lightning", "lightning.json",
                          twoSteps(parseLightningRequest, lightningCost, runLightning));
}

}  // namespace effectd
