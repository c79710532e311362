// POST /v1/fog — fog definitions -> weight tables (with their error), region lookups.
#include <algorithm>
#include <cmath>
#include <numbers>

#include <glm/geometric.hpp>

#include <effects/fog.h>
#include <effects/glow.h>
#include <render/render.h>

#include "api/api_common.h"
#include "api/api_fog.h"
#include "api/costs.h"
#include "api/shader_targets.h"
#include "contract/codec.h"

namespace effectd {

using nlohmann::json;
namespace fog = effects::fog;

fog::Fog parseFog(const json& j, const std::string& pointer) {
  fog::Fog f;
  f.type = *fog::fogTypeFromString(j.value("fogType", "LINEAR"));  // enums checked by the schema
  f.convention = *fog::conventionFromString(j.value("convention", fog::toString(f.convention)));
  if (j.contains("color")) f.color = toVec3(j["color"]);
  f.visibilityRange = j.value("visibilityRange", f.visibilityRange);
  f.start = j.value("start", f.start);
  f.end = j.value("end", f.end);
  f.density = j.value("density", f.density);
  f.distanceCoefficient = j.value("distanceCoefficient", f.distanceCoefficient);
  f.peak = j.value("peak", f.peak);
  f.heightFalloff = j.value("heightFalloff", f.heightFalloff);
  f.baseHeight = j.value("baseHeight", f.baseHeight);
  if (j.contains("extinction")) f.extinction = toVec3(j["extinction"]);
  if (j.contains("inscattering")) f.inscattering = toVec3(j["inscattering"]);
  f.startDistance = j.value("startDistance", f.startDistance);
  f.maxOpacity = j.value("maxOpacity", f.maxOpacity);
  f.cutoffDistance = j.value("cutoffDistance", f.cutoffDistance);
  if (j.contains("secondLayer")) {
    const json& l = j["secondLayer"];
    fog::HeightLayer layer;
    layer.density = l.value("density", layer.density);
    layer.heightFalloff = l.value("heightFalloff", layer.heightFalloff);
    layer.baseHeight = l.value("baseHeight", layer.baseHeight);
    f.secondLayer = layer;
  }
  if (j.contains("directional")) {
    const json& d = j["directional"];
    fog::Directional dir;
    if (d.contains("color")) dir.color = toVec3(d["color"]);
    if (d.contains("direction")) dir.direction = toVec3(d["direction"]);
    dir.g = d.value("g", dir.g);
    if (d.contains("exponent")) dir.exponent = d["exponent"].get<double>();
    dir.startDistance = d.value("startDistance", dir.startDistance);
    f.directional = dir;
  }
  if (auto e = fog::validate(f)) throwError(*e, pointer);
  return f;
}

// The schema guarantees exactly one of box or sphere.
fog::Region parseRegion(const json& j, const std::string& pointer) {
  fog::Region r;
  if (j.contains("box")) {
    r.shape = fog::Region::Shape::kBox;
    r.min = toVec3(j["box"]["min"]);
    r.max = toVec3(j["box"]["max"]);
  } else {
    r.shape = fog::Region::Shape::kSphere;
    r.center = toVec3(j["sphere"]["center"]);
    r.radius = j["sphere"]["radius"].get<double>();
  }
  r.fog = parseFog(j["fog"], pointer + "/fog");
  if (auto e = fog::validate(r)) throwError(*e, pointer);
  return r;
}

namespace {

void appendEncoded(std::string& bytes, float c, const std::string& encoding) {
  if (encoding == "rgba8") {
    bytes += char(static_cast<uint8_t>(std::lround(std::clamp(c, 0.0f, 1.0f) * 255.0f)));
  } else {
    uint16_t h = floatToHalf(c);
    bytes += char(h & 0xFF);
    bytes += char(h >> 8);
  }
}

// Values in order in the table's encoding (the glow's weight; ATMOSPHERIC's RGBA transmittance).
std::string encodeChannel(const std::vector<float>& values, const std::string& encoding) {
  std::string bytes;
  for (float v : values) appendEncoded(bytes, v, encoding);
  return base64Encode(bytes);
}

// The fog's own colour S reaching the eye at entry i: (1 - f) * colour, or ATMOSPHERIC's per channel.
glm::dvec3 scatteredAt(const fog::Table& t, const fog::Fog& f, size_t i) {
  if (t.scatteredRgb.empty()) return (1.0 - double(t.factor[i])) * f.color;
  return {t.scatteredRgb[3 * i], t.scatteredRgb[3 * i + 1], t.scatteredRgb[3 * i + 2]};
}

std::string encodeTexels(const fog::Table& t, const fog::Fog& f, const std::string& encoding) {
  // Texel = (S, f), S = (1 - f) * fogColor: the shader computes objectColour * a + rgb.
  std::string bytes;
  bytes.reserve(t.factor.size() * (encoding == "rgba8" ? 4 : 8));
  for (size_t i = 0; i < t.factor.size(); ++i) {
    const glm::dvec3 s = scatteredAt(t, f, i);
    float texel[4] = {float(s.r), float(s.g), float(s.b), t.factor[i]};
    for (float c : texel) appendEncoded(bytes, c, encoding);
  }
  return base64Encode(bytes);
}

json tableJson(const fog::Table& t, const fog::Fog& f, const std::string& encoding,
               const std::optional<std::vector<glm::dvec3>>& objectColors) {
  json out = {{"fogType", fog::toString(f.type)},
              {"size", t.width},
              {"range", {t.rangeStart, t.rangeEnd}},
              {"maxError", t.maxError},
              {"errorAtDistance", t.errorAtDistance}};
  if (std::isfinite(f.cutoffDistance)) out["cutoffDistance"] = f.cutoffDistance;
  if (t.height > 1) {
    out["elevations"] = t.height;
    if (t.layout == fog::TableOptions::Layout::kWarped) {  // (kLinear answers are as they were before layouts)
      const fog::WarpedAxes& a = t.warped;
      out["layout"] = fog::toString(t.layout);
      out["elevationAxis"] = "ray direction y at v = 1/2 + asinh(k y) / (2 asinh k), row 0 at v = 0 (straight down)";
      out["axes"] = {{"k", a.rowK},       {"factorStart", a.factorStart}, {"inscatterStart", a.inscatterStart},
                     {"end", a.end},      {"falloff", a.falloff},         {"kappa", a.kappa},
                     {"lambda", a.lambda}};
    } else {
      out["elevationAxis"] = "ray direction y from -1 (row 0) to 1";
    }
  }
  out["encoding"] = encoding;
  if (encoding == "json") {
    json factor = json::array(), contribution = json::array();
    for (size_t i = 0; i < t.factor.size(); ++i) {
      factor.push_back(t.factor[i]);
      const glm::dvec3 s = scatteredAt(t, f, i);
      for (int c = 0; c < 3; ++c) contribution.push_back(wire(s[c]));
    }
    if (!t.transmittanceRgb.empty()) out["transmittance"] = json(t.transmittanceRgb);
    out["factor"] = std::move(factor);
    out["fogContribution"] = std::move(contribution);
    if (!t.inscatter.empty()) out["inscatter"] = json(t.inscatter);
    if (objectColors) {
      json finals = json::array();
      for (const glm::dvec3& o : *objectColors) {
        json row = json::array();
        for (size_t i = 0; i < t.factor.size(); ++i) {
          const glm::dvec3 s = scatteredAt(t, f, i);
          for (size_t c = 0; c < 3; ++c) {
            const double tr = t.transmittanceRgb.empty() ? double(t.factor[i]) : double(t.transmittanceRgb[3 * i + c]);
            row.push_back(wire(tr * o[int(c)] + s[int(c)]));
          }
        }
        finals.push_back(std::move(row));
      }
      out["finalColors"] = std::move(finals);
    }
  } else {
    out["texelLayout"] =
        "RGBA = (S, f), S the fog's colour reaching the eye ((1-f)*fogColor; ATMOSPHERIC: per channel), row-major, " +
        std::string(encoding == "rgba8" ? "unsigned bytes" : "little-endian binary16");
    out["data"] = encodeTexels(t, f, encoding);
    if (!t.inscatter.empty()) out["inscatterData"] = encodeChannel(t.inscatter, encoding);
    if (!t.transmittanceRgb.empty()) {  // RGBA = (T, 1): the object's weight per channel
      std::vector<float> rgba;
      for (size_t i = 0; i < t.factor.size(); ++i)
        rgba.insert(rgba.end(),
                    {t.transmittanceRgb[3 * i], t.transmittanceRgb[3 * i + 1], t.transmittanceRgb[3 * i + 2], 1.0f});
      out["transmittanceData"] = encodeChannel(rgba, encoding);
    }
  }
  if (!t.transmittanceRgb.empty())
    out["transmittanceLayout"] =
        "ATMOSPHERIC: colour = object * transmittance + fogContribution, per channel; factor is the channels' mean";
  if (!t.inscatter.empty())
    out["inscatterLayout"] =
        "1 - f_dir per entry, as factor; colour += inscatter * directional.color * lobe(cos theta)";
  return out;
}

fog::TableOptions tableOptions(const json& o, const Config& config) {
  fog::TableOptions opt;
  opt.maxSize = config.limits.maxTableSize;
  opt.size = o.value("size", size_t(0));
  opt.maxError = o.value("maxError", 0.0);
  if (!o.contains("size") && !o.contains("maxError")) opt.size = 256;
  if (o.contains("range")) {
    opt.rangeStart = o["range"][0].get<double>();
    opt.rangeEnd = o["range"][1].get<double>();
  }
  opt.elevations = o.value("elevations", size_t(0));
  opt.cameraHeight = o.value("cameraHeight", 0.0);
  opt.layout = *fog::layoutFromString(o.value("layout", fog::toString(opt.layout)));
  opt.measureError = o.value("measureError", opt.measureError);
  return opt;
}

// The fog function an engine pastes into its own fragment shader (fog::shader, the
// renderer's own), in the asked language, with its uniforms' values for the asked camera.
json fogShaderJson(const FogRequest& request, const RequestContext& ctx, JsonReply& reply) {
  const fog::Fog& global = request.fog;
  const std::vector<fog::Region>& regions = request.regions;
  if (regions.size() > effects::render::kMaxFogRegions)
    throw fieldError(422, ctx.at + "/regions",
                     "the fog shader takes at most " + std::to_string(effects::render::kMaxFogRegions) + " regions");
  const std::string& language = request.shaderLanguage;
  effects::Stopwatch watch;
  const fog::FogShader fs = fog::shader(global, regions, request.shaderCamera);
  json uniforms = json::object();
  for (const auto& u : fs.uniforms) uniforms[u.name] = {{"type", u.type}, {"values", u.values}};
  json out = {{"language", language},
              {"function", "vec3 applyFog(vec3 rgb, vec3 world): rgb seen at world position world, fogged"},
              {"code", fs.glsl},
              {"uniforms", std::move(uniforms)}};
  if (ShaderTarget target; shaderTarget(language, target)) {
    // The snippet inside a fragment shader that calls it, so that every target keeps it.
    const std::string wrapper = "#version 330 core\nin vec3 vWorld;\nin vec3 vColor;\nout vec4 fragColor;\n" + fs.glsl +
                                "void main() { fragColor = vec4(applyFog(vColor, vWorld), 1.0); }\n";
    auto t = translateShader("", wrapper, target);
    if (!t.ok()) throwError(t.error());
    out["code"] = stageCode(t.value().fragment);
    out["entryPoint"] = t.value().fragment.entryPoint;
    out["resources"] = resourcesJson(t.value().resources);
    out["note"] =
        "a whole fragment shader (in vWorld, vColor; out the fogged colour) around applyFog, as the "
        "target language has it: take applyFog and its uniforms into your own shader";
  }
  reply.computeMs += watch.ms();
  return out;
}

// The glow of a light seen through this fog (include "glow"): its APSF kernel, as fitted
// Gaussians and as a radial table, with the light it misplaces against the series.
json glowJson(const FogRequest& request, const RequestContext& ctx, JsonReply& reply) {
  namespace gw = effects::glow;
  if (!request.glow) throw fieldError(400, ctx.at + "/glow", "is required when include has \"glow\"");
  const FogRequest::Glow& g = *request.glow;
  gw::Medium m;
  std::string thicknessFrom = "given";
  if (g.opticalThickness) {
    m.thickness = *g.opticalThickness;
  } else {
    m.thickness = gw::thicknessAlong(request.fog, request.regions, *g.camera, *g.source);
    thicknessFrom = "-ln(the fog's mean transmittance from camera to source)";
  }
  const int region = g.source ? fog::regionAt(request.regions, *g.source) : -1;
  m.forwardScattering = g.forwardScattering.value_or(
      gw::forwardScatteringOf(region < 0 ? request.fog : request.regions[size_t(region)].fog));
  auto k = gw::kernel(m, g.kernel);
  if (!k.ok()) throwError(k.error(), ctx.at + "/glow", {{"maxAngle", {ctx.at + "/glow/maxAngleDeg"}}});
  const gw::Kernel& kernel = k.value();
  reply.computeMs += kernel.stats.elapsedMs;
  reply.errorMs += kernel.stats.errorMs;
  constexpr double kDeg = 180 / std::numbers::pi;
  json table = {{"angleDeg", json::array()}, {"perSteradian", json::array()}};
  for (int i = 0; i < g.kernel.samples; ++i) {
    const double a = g.kernel.maxAngle * i / (g.kernel.samples - 1);
    table["angleDeg"].push_back(wire(a * kDeg));
    table["perSteradian"].push_back(wire(gw::kernelAt(kernel, a)));
  }
  json out = {{"opticalThickness", m.thickness},  // a double: T may pass a float's range
              {"opticalThicknessFrom", thicknessFrom},
              {"forwardScattering", wire(m.forwardScattering)},
              {"shapeThickness", kernel.shapeThickness},
              {"direct", wire(kernel.direct)},
              {"scattered", wire(kernel.scattered)},
              {"method", gw::toString(kernel.method)},
              {"haloRadiusDeg", wire(kernel.haloRadius * kDeg)},
              {"maxAngleDeg", wire(kernel.maxAngle * kDeg)},
              {"table", std::move(table)},
              {"seriesTerms", int(kernel.stats.counters.at("seriesTerms"))}};
  if (!kernel.gaussians.empty()) {
    json list = json::array();
    for (const gw::Gaussian& gs : kernel.gaussians) list.push_back({{"weight", wire(gs.weight)}, {"sigmaDeg", wire(gs.sigma * kDeg)}});
    out["gaussians"] = std::move(list);
  }
  if (kernel.misplaced)
    out["error"] = {{"misplaced", wire(*kernel.misplaced)},
                    {"metric", kernel.stats.errorMetric},
                    {"reference", kernel.stats.reference},
                    {"kind", "measured"}};
  return out;
}

}  // namespace

FogRequest parseFogRequest(const json& body, const RequestContext& ctx) {
  FogRequest r;
  r.include = Includes(body, kFogIncludes);
  r.fog = parseFog(body["fog"], ctx.at + "/fog");
  if (body.contains("regions"))
    for (size_t i = 0; i < body["regions"].size(); ++i)
      r.regions.push_back(parseRegion(body["regions"][i], ctx.at + "/regions/" + std::to_string(i)));
  r.table = tableOptions(body.value("table", json::object()), ctx.config);
  r.encoding = body.value("table", json::object()).value("encoding", r.encoding);
  if (body.contains("objectColors")) {
    r.objectColors.emplace();
    for (const json& c : body["objectColors"]) r.objectColors->push_back(toVec3(c));
  }
  if (body.contains("samples")) {
    const json& s = body["samples"];
    r.samples = FogRequest::Samples{toVec3(s["camera"]), {}};
    for (const json& p : s["points"]) r.samples->points.push_back(toVec3(p));
  }
  const json shader = body.value("shader", json::object());
  r.shaderLanguage = shader.value("language", r.shaderLanguage);
  if (shader.contains("camera")) r.shaderCamera = toVec3(shader["camera"]);
  if (body.contains("glow")) {
    const json& g = body["glow"];
    FogRequest::Glow glow;
    if (g.contains("camera")) glow.camera = toVec3(g["camera"]);
    if (g.contains("source")) glow.source = toVec3(g["source"]);
    if (g.contains("opticalThickness")) glow.opticalThickness = g["opticalThickness"].get<double>();
    if (g.contains("forwardScattering")) glow.forwardScattering = g["forwardScattering"].get<double>();
    glow.kernel.method = *effects::glow::methodFromString(g.value("kernel", "gaussians-3"));  // the schema's enum
    glow.kernel.samples = g.value("samples", glow.kernel.samples);
    if (g.contains("maxAngleDeg")) glow.kernel.maxAngle = g["maxAngleDeg"].get<double>() * std::numbers::pi / 180;
    glow.kernel.measureError = g.value("measureError", glow.kernel.measureError);
    if (!glow.opticalThickness && !(glow.camera && glow.source))
      throw fieldError(400, ctx.at + "/glow", "needs opticalThickness, or camera and source (the ray through the fog)");
    r.glow = glow;
  }
  return r;
}

JsonReply runFog(const FogRequest& request, const json& /*body*/, const RequestContext& ctx) {
  const Includes& include = request.include;
  const fog::Fog& global = request.fog;
  const std::vector<fog::Region>& regions = request.regions;

  JsonReply reply;
  reply.method = std::string("table-") + fog::toString(global.type);
  if (global.convention != fog::Convention::kEffectd)
    reply.method += std::string("-") + fog::toString(global.convention);
  json out = {{"method", reply.method}};
  json stats = json::array();
  auto build = [&](const fog::Fog& f, const std::string& pointer) {
    auto t = fog::buildTable(f, request.table);
    // The table's options sit under "table"; the fog's own parameters under its pointer.
    if (!t.ok())
      throwError(t.error(), pointer,
                 {{"range", {ctx.at + "/table/range"}},
                  {"size", {ctx.at + "/table/size", 1, "--max-table-size"}},
                  {"maxError", {ctx.at + "/table/maxError"}}});
    reply.computeMs += t.value().stats.elapsedMs;
    reply.errorMs += t.value().stats.errorMs;
    stats.push_back(statsJson(t.value().stats));
    return tableJson(t.value(), f, request.encoding, request.objectColors);
  };
  if (include.has("table")) {
    out["table"] = build(global, ctx.at + "/fog");
    const bool measured = request.table.measureError || request.table.size == 0;  // maxError: always
    out["error"] = {{"maxError", out["table"]["maxError"]},
                    {"kind", measured ? "measured" : "estimate"},
                    {"metric", measured ? "max |linear interpolation of the table - exact f|"
                                        : "estimate of max |linear interpolation - exact f|: the table's largest "
                                          "|second difference| / 8 (table.measureError false)"},
                    {"reference", global.convention == fog::Convention::kEffectd
                                      ? "exact closed form"
                                      : std::string("the closed form of the ") + fog::toString(global.convention) +
                                            " convention (its shader's formula in double precision)"}};
  }
  if (include.has("regionTables")) {
    json list = json::array();
    for (size_t i = 0; i < regions.size(); ++i)
      list.push_back(build(regions[i].fog, ctx.at + "/regions/" + std::to_string(i) + "/fog"));
    out["regionTables"] = std::move(list);
  }
  if (include.has("samples")) {
    if (!request.samples)
      throw fieldError(400, ctx.at + "/samples", "is required when include has \"samples\"");
    effects::Stopwatch watch;
    json list = json::array();
    for (const glm::dvec3& point : request.samples->points) {
      const fog::Sample at = fog::sampleAt(global, regions, request.samples->camera, point);
      const fog::Fog& f = at.region < 0 ? global : regions[size_t(at.region)].fog;
      json sample = {{"region", at.region}, {"factor", wire(at.factor)}};
      if (f.type == fog::FogType::kAtmospheric || f.directional) {  // colour = object * T + fogColor
        sample["transmittance"] = {wire(at.transmittance.r), wire(at.transmittance.g), wire(at.transmittance.b)};
        sample["fogColor"] = {wire(at.fogColor.r), wire(at.fogColor.g), wire(at.fogColor.b)};
      }
      list.push_back(std::move(sample));
    }
    reply.computeMs += watch.ms();
    out["samples"] = std::move(list);
  }
  if (include.has("shader")) out["shader"] = fogShaderJson(request, ctx, reply);
  if (include.has("glow")) out["glow"] = glowJson(request, ctx, reply);
  if (include.has("stats")) out["stats"] = std::move(stats);
  reply.body = std::move(out);
  return reply;
}

JsonReply handleFog(const json& body, const RequestContext& ctx) {
  return runFog(parseFogRequest(body, ctx), body, ctx);
}

void addFogEndpoints(Service& service) {
  service.addJsonEndpoint("/v1/fog", "fog.json", twoSteps(parseFogRequest, fogCost, runFog));
}

}  // namespace effectd
