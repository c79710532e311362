// POST /v1/bubble — seed 000's bubble: mesh, uniforms, GLSL variants, thin-film table, glTF.
#include <algorithm>
#include <map>
#include <memory>
#include <mutex>

#include <glm/geometric.hpp>

#include <effects/bubble.h>
#include <render/render.h>

#include "api/api_bubble.h"
#include "api/api_common.h"
#include "api/bubble_glb.h"
#include "api/costs.h"
#include "api/error_estimates.h"
#include "api/shader_targets.h"
#include "contract/codec.h"

namespace effectd {

using nlohmann::json;
namespace bb = effects::bubble;
namespace rd = effects::render;

bb::Params parseBubbleParams(const json& j, const std::string& pointer) {
  bb::Params p;
  p.n1 = j.value("n1", p.n1);
  p.n2 = j.value("n2", p.n2);
  p.deltaSpeed = j.value("deltaSpeed", p.deltaSpeed);
  p.betaSpeed = j.value("betaSpeed", p.betaSpeed);
  p.rimPower = j.value("rimPower", p.rimPower);
  p.muSpeed = j.value("muSpeed", p.muSpeed);
  if (j.value("wobbleVariant", "relative") == "paper") p.wobbleVariant = bb::WobbleVariant::kPaper;
  const bb::WobbleShape defaults = bb::wobbleDefaults(p.wobbleVariant);
  p.wobbleAmplitude = j.value("wobbleAmplitude", defaults.amplitude);
  p.wobbleFrequency = j.value("wobbleFrequency", defaults.frequency);
  if (auto e = bb::validate(p)) throwError(*e, pointer);
  return p;
}

bb::Features parseBubbleFeatures(const json& body) {
  const json j = body.value("features", json::object());
  bb::Features f;
  f.reflection = j.value("reflection", f.reflection);
  f.refraction = j.value("refraction", f.refraction);
  f.rim = j.value("rim", f.rim);
  f.textureFlow = j.value("textureFlow", f.textureFlow);
  f.wobble = j.value("wobble", f.wobble);
  f.iridescence = j.value("iridescence", f.iridescence);
  f.thickness = j.value("thickness", f.thickness);
  f.backFace = j.value("backFace", f.backFace);
  f.highlight = j.value("highlight", f.highlight);
  if (body.value("shading", "film") == "paper") f.shading = bb::Shading::kPaper;
  return f;
}

bb::ThicknessOptions parseFilm(const json& body, const Config& config, const std::string& pointer) {
  const json j = body.value("film", json::object());
  bb::ThicknessOptions o;
  o.seed = j.value("seed", o.seed);
  o.bottomStartNm = j.value("bottomStartNm", o.bottomStartNm);
  o.bottomEndNm = j.value("bottomEndNm", o.bottomEndNm);
  o.swirl = j.value("swirl", o.swirl);
  o.swirlSpeed = j.value("swirlSpeed", o.swirlSpeed);
  o.width = j.value("width", o.width);
  o.height = j.value("height", o.height);
  if (auto e = bb::validate(o)) throwError(*e, pointer + "/film");
  if (size_t(o.width) * size_t(o.height) > config.limits.maxThinFilmTexels)
    throw fieldError(413, pointer + "/film/width",
                     "a " + std::to_string(o.width) + "x" + std::to_string(o.height) +
                         " thickness texture exceeds the limit of " + std::to_string(config.limits.maxThinFilmTexels) +
                         " texels (--max-thin-film-texels)");
  return o;
}

std::vector<bb::Light> parseLights(const json& body, const std::string& pointer) {
  if (!body.contains("lights")) return {bb::Light{}};
  std::vector<bb::Light> out;
  for (size_t i = 0; i < body["lights"].size(); ++i) {
    const json& l = body["lights"][i];
    const std::string at = pointer + "/lights/" + std::to_string(i);
    bb::Light light;
    if (l.contains("direction")) light.direction = toVec3(l["direction"]);
    requireNonZero(light.direction, at + "/direction");
    // Scaled by its largest component first: [1e-300, 0, 0] normalises without underflow.
    const glm::dvec3 a = glm::abs(light.direction);
    light.direction = glm::normalize(light.direction / std::max({a.x, a.y, a.z}));
    if (l.contains("color")) light.color = toVec3(l["color"]);
    light.intensity = l.value("intensity", light.intensity);
    light.sizeDegrees = l.value("sizeDegrees", light.sizeDegrees);
    out.push_back(light);
  }
  return out;
}

json thicknessRange(const json& body, const bb::Features& f, const bb::ThicknessOptions& film) {
  const json tf = body.value("thinFilm", json::object());
  if (tf.contains("thicknessRange")) return tf["thicknessRange"];
  if (f.shading == bb::Shading::kPaper) return json{0, 1000};
  return json{0, std::max({1000.0, film.bottomStartNm, film.bottomEndNm})};  // the film's thickest
}

namespace {

// The body's "thinFilm" table options, not yet checked against the limit.
bb::ThinFilmOptions readThinFilm(const json& body, const bb::Params& params, const json& range) {
  const json tf = body.value("thinFilm", json::object());
  bb::ThinFilmOptions o;
  o.ior = params.n2;
  o.wavelengths = tf.value("wavelengths", o.wavelengths);
  o.measureError = tf.value("measureError", o.measureError);
  o.width = tf.value("width", o.width);
  o.height = tf.value("height", o.height);
  o.thicknessMinNm = range[0].get<double>();
  o.thicknessMaxNm = range[1].get<double>();
  return o;
}


}  // namespace

void checkThinFilmSize(const bb::ThinFilmOptions& o, const Config& config, const std::string& pointer) {
  if (size_t(o.width) * size_t(o.height) > config.limits.maxThinFilmTexels)
    throw fieldError(413, pointer + "/thinFilm/width",
                     "a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " table exceeds the limit of " +
                         std::to_string(config.limits.maxThinFilmTexels) + " texels (--max-thin-film-texels)");
}

namespace {

// Values for the uniforms the CPU owns; only those the shader variant declares are sent.
json uniforms(const bb::Params& p, const bb::ThicknessOptions& film, const std::vector<bb::Light>& lights,
              const std::vector<std::string>& declared, double t, double radius, const json& thicknessRange) {
  const bb::Film mu = bb::film(p, t);
  const bb::WobbleShape wobble = bb::wobbleInObject(p, radius);
  json all = {{"uWobblePhase", bb::reducedPhase(p.deltaSpeed, t)},
              {"uWobbleAmplitude", wobble.amplitude},
              {"uWobbleFrequency", wobble.frequency},
              {"uFilmTop", mu.top},
              {"uFilmBottom", mu.bottom},
              {"uEta", p.n1 / p.n2},
              {"uFlowPhase", bb::reducedPhase(p.betaSpeed, t)},
              {"uRimPower", p.rimPower},
              {"uThickness", mu.top},
              {"uThicknessRange", thicknessRange},
              {"uThicknessNm", bb::equatorThickness(p, film, t)},
              {"uPass", 0}};
  const glm::dvec4 base = rd::Bubble{}.baseColor;  // the preview's (scene bubbleStyle.baseColor)
  all["uBaseColor"] = {base.r, base.g, base.b, base.a};
  json directions = json::array(), radiances = json::array(), sharpness = json::array();
  for (size_t i = 0; i < lights.size() && i < size_t(bb::kMaxLights); ++i) {
    const glm::dvec3 d = glm::normalize(lights[i].direction), r = lights[i].color * lights[i].intensity;
    directions.push_back({d.x, d.y, d.z});
    radiances.push_back({r.x, r.y, r.z});
    sharpness.push_back(bb::highlightSharpness(lights[i]));
  }
  all["uLightCount"] = directions.size();
  all["uLightDirection"] = directions;
  all["uLightRadiance"] = radiances;
  all["uLightSharpness"] = sharpness;
  json out = json::object();
  for (const std::string& name : declared)
    if (all.contains(name)) out[name] = all[name];
  return out;
}

// The icosphere with its MikkTSpace frames (and per-vertex final vectors and rim when the body
// gives a camera): wobbled at `time` when `wobbled`, else the rest shape (the shader that comes
// with it displaces the vertices itself).
}  // namespace

FieldTable meshFields(const std::string& at) {
  return {{"level", {at + "/mesh/level"}}, {"radius", {at + "/mesh/radius"}}};
}

namespace {

bb::Mesh buildMesh(const BubbleRequest& request, bool wobbled, const RequestContext& ctx) {
  bb::MeshOptions o = request.mesh;
  o.t = request.time.value_or(0.0);
  o.wobble = request.features.wobble && wobbled;
  o.parallel = ctx.parallel;
  // The rest shape comes with a shader that wobbles it: the same float32 limit holds.
  if (request.features.wobble && !wobbled)
    if (auto e = bb::wobbleFits(request.params, o.radius)) throwError(*e, ctx.at + "/mesh");
  auto r = bb::icosphere(request.params, o);
  if (!r.ok()) throwError(r.error(), ctx.at, meshFields(ctx.at));
  return std::move(r.value());
}

// The mesh as flat arrays; uvOrigin top-left negates tangent w, as /v1/tangents does.
json meshJson(bb::Mesh mesh, bool topLeft, bool wobbled) {
  if (topLeft)
    for (auto& t : mesh.tangents) t.w = -t.w;
  json mj = {{"vertexCount", mesh.positions.size()},
             {"positions", flat<3>(mesh.positions)},
             {"normals", flat<3>(mesh.normals)},
             {"uvs", flat<2>(mesh.uvs)},
             {"tangents", flat<4>(mesh.tangents)},
             {"indices", mesh.indices},
             {"wobbled", wobbled}};
  if (!mesh.finalVectors.empty()) {
    mj["finalVectors"] = flat<3>(mesh.finalVectors);
    mj["rim"] = mesh.rim;
  }
  return mj;
}

// The physical thin-film table over thickness x cos(theta), as JSON numbers or RGBA16F base64.
json thinFilmJson(const BubbleRequest& request, const json& tf, const RequestContext& ctx, effects::Stats& stats) {
  const bb::ThinFilmOptions& o = request.thinFilm;
  checkThinFilmSize(o, ctx.config, ctx.at);
  const json& range = request.thicknessRange;
  auto r = bb::thinFilmTable(o);
  // The table's index of refraction is the film's own, params.n2 (the thin film has no ior): an
  // n2 the schema allows but the table cannot take is a 422 at /params/n2.
  if (!r.ok() && r.error().field == "/ior")
    throw fieldError(422, ctx.at + "/params/n2", "the thin film's table takes n2 in [1, 3]: " + r.error().message);
  if (!r.ok()) throwError(r.error(), ctx.at + "/thinFilm");
  const bb::ThinFilmTable& table = r.value();
  json j = {{"width", table.width},
            {"height", table.height},
            {"axes", "u: thickness from thicknessRange[0] (column 0) to [1] nm; v: cos(theta) from 0 (row 0) to 1"},
            {"thicknessRange", range},
            {"wavelengths", o.wavelengths},
            {"colorSpace", "linear sRGB, D65, reflectance of the film (white-balanced: R = 1 gives 1)"},
            {"meanDeltaE", table.meanDeltaE},
            {"maxDeltaE", table.maxDeltaE},
            {"errorKind", table.stats.errorKind},
            {"errorMetric", table.stats.errorMetric},
            {"reference", table.stats.reference}};
  if (tf.value("encoding", "json") == "json") {
    json rgb = json::array();
    for (float v : table.rgb) rgb.push_back(v);
    j["rgb"] = std::move(rgb);
  } else {
    std::string bytes;
    for (size_t i = 0; i < table.rgb.size(); i += 3)
      for (float c : {table.rgb[i], table.rgb[i + 1], table.rgb[i + 2], 1.0f}) {
        uint16_t h = floatToHalf(c);
        bytes += char(h & 0xFF);
        bytes += char(h >> 8);
      }
    j["encoding"] = "rgba16f";
    j["data"] = base64Encode(bytes);
  }
  stats = table.stats;
  return j;
}

// The variant for another engine, translated once per process and feature set (the shader
// cache: the same features and language give the same bytes, as the ETag does).
std::shared_ptr<const TranslatedShader> translated(const bb::Features& f, ShaderTarget target,
                                                   const bb::ShaderSource& glsl, bool& cached) {
  static std::mutex mu;
  static std::map<std::string, std::shared_ptr<const TranslatedShader>> cache;
  const std::string key = std::to_string(int(target)) + ":" + bb::variantKey(f);
  {
    std::lock_guard<std::mutex> lock(mu);
    if (auto it = cache.find(key); it != cache.end()) return cached = true, it->second;
  }
  auto r = translateShader(glsl.vertex, glsl.fragment, target);
  if (!r.ok()) throwError(r.error());
  auto shared = std::make_shared<const TranslatedShader>(std::move(r.value()));
  std::lock_guard<std::mutex> lock(mu);
  cache.emplace(key, shared);  // at most 2^9 x 2 feature sets x 3 targets: bounded
  return cached = false, shared;
}

// `uniforms` (and eqn 9's flowOffset beside them) and `shader`, as `include` asks; a
// translation's cache state and compile time go to `reply`.
void addShaderParts(const BubbleRequest& request, double t, json& out, JsonReply& reply) {
  const Includes& include = request.include;
  const bb::Params& params = request.params;
  const bb::Features& features = request.features;
  // Every language declares the same uniforms, so one variant serves uniforms and shader;
  // SPIR-V, HLSL and MSL are translated from the 330 core source.
  const std::string& language = request.shaderLanguage;
  const bool es = language == "glsl-es-300";
  bb::ShaderSource s;
  if (include.has("uniforms") || include.has("shader"))
    s = bb::shader(features, es ? bb::Glsl::kEs300 : bb::Glsl::kCore330);
  if (include.has("uniforms"))
    out["uniforms"] = uniforms(params, request.film, request.lights, s.uniforms, t, request.mesh.radius,
                               request.thicknessRange);
  if (include.has("uniforms") && features.shading == bb::Shading::kPaper && features.textureFlow) {
    const glm::dvec2 off = bb::flowOffset(params, t);  // eqn 9, for clients that offset on the CPU
    out["flowOffset"] = {off.x, off.y};
  }
  if (include.has("uniforms") || include.has("shader")) {
    const ErrorEstimate e = shadingErrorEstimate(features);
    out["shadingError"] = {{"meanDeltaE", e.value},
                           {"limit", e.limit},
                           {"kind", "estimate"},
                           {"variant", e.row},
                           {"reference", "the variant's frame against CPU ray tracing (400 wavelengths) on the error "
                                         "report's scene (docs/error-vs-time.md, Render previews)"}};
  }
  if (!include.has("shader")) return;
  const bool filmModel = features.shading == bb::Shading::kFilm;
  json shader = {{"language", language},
                 {"vertex", s.vertex},
                 {"fragment", s.fragment},
                 {"entryPoints", {{"vertex", "main"}, {"fragment", "main"}}},
                 {"uniforms", s.uniforms},
                 {"attributes", s.attributes},
                 {"blend", filmModel ? "uPass 0: colour ZERO, SRC_COLOR, alpha ZERO, SRC_ALPHA; uPass 1: ONE, ONE (or "
                                       "uPass 2 alone: ONE, ONE_MINUS_SRC_ALPHA, grey transmission)"
                                     : "colour SRC_ALPHA, ONE_MINUS_SRC_ALPHA; alpha ONE, ONE_MINUS_SRC_ALPHA"},
                 {"draw", std::string(filmModel && features.backFace ? "back faces (cull front), then front faces "
                                                                       "(cull back)"
                                                                     : "front faces (cull back)") +
                              (filmModel ? ", each with uPass 0 then 1" : "") + "; depth test, no depth write"}};
  if (ShaderTarget target; shaderTarget(language, target)) {
    bool cached = false;
    const auto t = translated(features, target, s, cached);
    shader["vertex"] = stageCode(t->vertex);
    shader["fragment"] = stageCode(t->fragment);
    shader["entryPoints"] = {{"vertex", t->vertex.entryPoint}, {"fragment", t->fragment.entryPoint}};
    shader["resources"] = resourcesJson(t->resources);
    if (target == ShaderTarget::kSpirv) shader["encoding"] = "base64: SPIR-V 1.0 words, little-endian (Vulkan 1.0)";
    reply.runHeaders["X-Shader-Cache"] = cached ? "hit" : "miss";
    if (!cached) {  // already inside the caller's compute time
      reply.runHeaders["X-Shader-Compile-Ms"] = std::to_string(t->compileMs);
      reply.stages.emplace_back("shader", t->compileMs);
    }
  }
  out["shader"] = std::move(shader);
}

// The film's thickness texture over the mesh's UVs, as JSON numbers or float32 base64.
json thicknessJson(const bb::ThicknessField& f, const std::string& encoding) {
  json j = {{"width", f.width},
            {"height", f.height},
            {"axes",
             "equirectangular as the mesh's uvs: u = atan2(z, x) / 2 pi + 0.5 (wrap), v = 0 (row 0) at the "
             "bottom (y = -1) to 1 at the top"},
            {"unit", "nm"},
            {"meanErrorNm", f.meanErrorNm},
            {"maxErrorNm", f.maxErrorNm}};
  if (encoding == "json") {
    j["nm"] = f.nm;
  } else {
    j["encoding"] = "r32f";
    j["data"] = base64Encode(std::string(reinterpret_cast<const char*>(f.nm.data()), f.nm.size() * sizeof(float)));
  }
  return j;
}

// The thickness as glTF wants it: G = thickness / max, 16 bits, rows as the mesh's v.
std::string thicknessPng(const bb::ThicknessField& f, double maxNm) {
  rd::Image image;
  image.width = f.width;
  image.height = f.height;
  image.rgba.assign(size_t(f.width) * size_t(f.height) * 4, 1.0f);
  for (size_t i = 0; i < f.nm.size(); ++i) image.rgba[i * 4 + 1] = float(std::clamp(f.nm[i] / maxNm, 0.0, 1.0));
  auto png = rd::encodePng(image, 16);
  if (!png.ok()) throwError(png.error(), "/film");
  return std::move(png.value());
}

bb::ThicknessField thicknessField(const bb::Params& params, const bb::ThicknessOptions& o, double t,
                                  const RequestContext& ctx) {
  auto r = bb::thicknessField(params, o, t, ctx.parallel);
  if (!r.ok()) throwError(r.error(), ctx.at + "/film");
  return std::move(r.value());
}

}  // namespace

BubbleRequest parseBubbleRequest(const json& body, const RequestContext& ctx) {
  BubbleRequest r;
  r.include = Includes(body, kBubbleIncludes);
  r.glb = body.value("format", "json") == "glb";
  r.params = parseBubbleParams(body.value("params", json::object()), ctx.at + "/params");
  r.features = parseBubbleFeatures(body);
  r.film = parseFilm(body, ctx.config, ctx.at);
  r.lights = parseLights(body, ctx.at);
  if (body.contains("time")) r.time = body["time"].get<double>();
  r.thicknessRange = thicknessRange(body, r.features, r.film);
  r.thicknessRangeGiven = body.value("thinFilm", json::object()).contains("thicknessRange");
  r.thinFilm = readThinFilm(body, r.params, r.thicknessRange);
  r.shaderLanguage = body.value("shader", json::object()).value("language", r.shaderLanguage);
  if (body.contains("motion")) {
    const json& m = body["motion"];
    r.motion = BubbleRequest::Motion{toVec3(m["from"]), toVec3(m["to"]), m["s"].get<double>()};
  }
  const json m = body.value("mesh", json::object());
  r.meshLevelGiven = m.contains("level");
  r.mesh.level = m.value("level", r.mesh.level);
  r.mesh.maxLevel = kMaxIcosphereLevel;
  r.mesh.radius = m.value("radius", r.mesh.radius);
  if (body.contains("camera")) r.mesh.camera = toVec3(body["camera"]);
  return r;
}

// Long because it is the list of what /v1/bubble can include (glb, motion, shader parts, mesh,
// thin-film table, thickness), each computed only when asked for, in the answer's order.
JsonReply runBubble(const BubbleRequest& request, const json& body, const RequestContext& ctx) {
  const Includes& include = request.include;
  const bb::Params& params = request.params;
  const bb::Features& features = request.features;
  const bool film = features.shading == bb::Shading::kFilm;
  const bb::ThicknessOptions& filmOptions = request.film;
  const double t = request.time.value_or(0.0);
  const json& range = request.thicknessRange;
  // glTF: the film model's own thickness (the field's texture over [0, its thickest], or one
  // thickness); the paper's iridescence the thin-film range (glTF's default 100-400 nm unless given).
  GltfFilm gltf;
  gltf.iridescent = film || features.iridescence;
  if (film) {
    gltf.minNm = 0;
    gltf.maxNm = features.thickness ? std::max({filmOptions.bottomStartNm, filmOptions.bottomEndNm, 1.0})
                                    : bb::equatorThickness(params, filmOptions, t);
  } else if (request.thicknessRangeGiven) {
    gltf.minNm = range[0].get<double>();
    gltf.maxNm = range[1].get<double>();
  }
  JsonReply reply;
  reply.method = film ? "thin-film" : "seed000";
  if (request.glb) {                                      // the whole bubble as one file instead of JSON
    const bb::Mesh mesh = buildMesh(request, true, ctx);  // no shader in a GLB
    reply.computeMs = mesh.stats.elapsedMs;
    if (film && features.thickness) {
      const bb::ThicknessField field = thicknessField(params, filmOptions, t, ctx);
      reply.computeMs += field.stats.elapsedMs;
      gltf.thicknessPng = thicknessPng(field, gltf.maxNm);
    }
    reply.binary = bubbleGlb(mesh, params, gltf);
    reply.contentType = "model/gltf-binary";
    return reply;
  }
  json out = {{"method", reply.method}};
  json stats = json::array();
  effects::Stopwatch watch;

  if (request.motion) {
    const glm::dvec3 c = bb::moveTowards(request.motion->from, request.motion->to, request.motion->s);
    out["position"] = {c.x, c.y, c.z};
  }
  addShaderParts(request, t, out, reply);
  reply.computeMs += watch.ms();
  if (include.has("mesh")) {
    // One wobble, not two: with the shader (whose vertex stage wobbles by uWobble*) the mesh is
    // the rest shape; alone it carries the wobble at `time`.
    const bool wobbled = features.wobble && !include.has("shader");
    bb::Mesh mesh = buildMesh(request, wobbled, ctx);
    reply.computeMs += mesh.stats.elapsedMs;
    stats.push_back(statsJson(mesh.stats));
    out["mesh"] = meshJson(std::move(mesh), body.value("uvOrigin", "bottom-left") == "top-left", wobbled);
  }
  if (include.has("thickness")) {
    const bb::ThicknessField field = thicknessField(params, filmOptions, t, ctx);
    reply.computeMs += field.stats.elapsedMs;
    stats.push_back(statsJson(field.stats));
    out["thickness"] = thicknessJson(field, body.value("film", json::object()).value("encoding", "json"));
  }
  if (include.has("thinFilm")) {
    effects::Stats st;
    out["thinFilm"] = thinFilmJson(request, body.value("thinFilm", json::object()), ctx, st);
    reply.computeMs += st.elapsedMs;
    reply.errorMs += st.errorMs;
    stats.push_back(statsJson(st));
  }
  if (include.has("gltf")) {
    json ext = {{"iridescenceFactor", gltf.iridescent ? 1.0 : 0.0},
                {"iridescenceIor", params.n2},
                {"iridescenceThicknessMinimum", gltf.minNm},
                {"iridescenceThicknessMaximum", gltf.maxNm}};
    out["gltf"] = {{"KHR_materials_iridescence", ext}, {"KHR_materials_ior", {{"ior", baseIor(params, gltf)}}}};
    if (film && features.thickness)
      out["gltf"]["thicknessTexture"] =
          "iridescenceThicknessTexture: the thickness texture (include thickness) with G = nm / "
          "iridescenceThicknessMaximum (format glb embeds it)";
  }
  if (include.has("stats")) out["stats"] = std::move(stats);
  reply.body = std::move(out);
  return reply;
}

JsonReply handleBubble(const json& body, const RequestContext& ctx) {
  return runBubble(parseBubbleRequest(body, ctx), body, ctx);
}

void addBubbleEndpoints(Service& service) {
  service.addJsonEndpoint("/v1/bubble", "bubble.json", twoSteps(parseBubbleRequest, bubbleCost, runBubble));
}

}  // namespace effectd
