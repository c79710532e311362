// POST /v1/bubble — seed 000's bubble: mesh, uniforms, GLSL variants, thin-film table, glTF.
#include <algorithm>

#include <effects/bubble.h>

#include "api_bubble.h"
#include "api_common.h"
#include "bubble_glb.h"
#include "codec.h"
#include "costs.h"

namespace effectd {

using nlohmann::json;
namespace bb = effects::bubble;

bb::Params parseBubbleParams(const json& j, const std::string& pointer) {
  bb::Params p;
  p.n1 = j.value("n1", p.n1);
  p.n2 = j.value("n2", p.n2);
  p.deltaSpeed = j.value("deltaSpeed", p.deltaSpeed);
  p.betaSpeed = j.value("betaSpeed", p.betaSpeed);
  p.rimPower = j.value("rimPower", p.rimPower);
  p.muSpeed = j.value("muSpeed", p.muSpeed);
  p.wobbleAmplitude = j.value("wobbleAmplitude", p.wobbleAmplitude);
  if (auto e = bb::validate(p)) throwError(*e, pointer);
  return p;
}

bb::Features parseBubbleFeatures(const json& j) {
  bb::Features f;
  f.reflection = j.value("reflection", f.reflection);
  f.refraction = j.value("refraction", f.refraction);
  f.rim = j.value("rim", f.rim);
  f.textureFlow = j.value("textureFlow", f.textureFlow);
  f.wobble = j.value("wobble", f.wobble);
  f.iridescence = j.value("iridescence", f.iridescence);
  return f;
}

bb::ThinFilmOptions thinFilmOptions(const json& body, const bb::Params& params, const Config& config,
                                    const std::string& pointer) {
  const json tf = body.value("thinFilm", json::object());
  const json range = tf.value("thicknessRange", json{0, 1000});
  bb::ThinFilmOptions o;
  o.ior = params.n2;
  o.wavelengths = tf.value("wavelengths", 16);
  o.width = tf.value("width", 256);
  o.height = tf.value("height", 256);
  o.thicknessMinNm = range[0].get<double>();
  o.thicknessMaxNm = range[1].get<double>();
  if (size_t(o.width) * size_t(o.height) > config.limits.maxThinFilmTexels)
    throw fieldError(413, pointer + "/thinFilm/width",
                     "a " + std::to_string(o.width) + "x" + std::to_string(o.height) + " table exceeds the limit of " +
                         std::to_string(config.limits.maxThinFilmTexels) + " texels (--max-thin-film-texels)");
  return o;
}

namespace {

// Values for the uniforms the CPU owns; only those the shader variant declares are sent.
json uniforms(const bb::Params& p, const std::vector<std::string>& declared, double t) {
  const bb::Film film = bb::film(p, t);
  const double flow = bb::reducedPhase(p.betaSpeed, t);
  json all = {{"uWobblePhase", bb::reducedPhase(p.deltaSpeed, t)},
              {"uWobbleAmplitude", p.wobbleAmplitude},
              {"uFilmTop", film.top},
              {"uFilmBottom", film.bottom},
              {"uEta", p.n1 / p.n2},
              {"uFlowPhase", flow},
              {"uRimPower", p.rimPower},
              {"uThickness", film.top}};
  json out = json::object();
  for (const std::string& name : declared)
    if (all.contains(name)) out[name] = all[name];
  return out;
}

// The wobbled icosphere with its MikkTSpace frames (and per-vertex final vectors and rim
// when the body gives a camera).
bb::Mesh buildMesh(const json& body, const bb::Params& params, const bb::Features& features, double t,
                   const RequestContext& ctx) {
  const json m = body.value("mesh", json::object());
  bb::MeshOptions o;
  o.level = m.value("level", o.level);
  o.maxLevel = kMaxIcosphereLevel;
  o.radius = m.value("radius", 1.0);
  o.t = t;
  o.wobble = features.wobble;
  o.parallel = ctx.parallel;
  if (body.contains("camera")) o.camera = toVec3(body["camera"]);
  auto r = bb::icosphere(params, o);
  if (!r.ok()) {
    effects::Error e = r.error();
    throwError(e, ctx.at + (e.field == "/level" || e.field == "/radius" ? "/mesh" : ""));
  }
  return std::move(r.value());
}

// The mesh as flat arrays; uvOrigin top-left negates tangent w, as /v1/tangents does.
json meshJson(bb::Mesh mesh, bool topLeft) {
  if (topLeft)
    for (auto& t : mesh.tangents) t.w = -t.w;
  json mj = {{"vertexCount", mesh.positions.size()}, {"positions", flat<3>(mesh.positions)},
             {"normals", flat<3>(mesh.normals)},     {"uvs", flat<2>(mesh.uvs)},
             {"tangents", flat<4>(mesh.tangents)},   {"indices", mesh.indices}};
  if (!mesh.finalVectors.empty()) {
    mj["finalVectors"] = flat<3>(mesh.finalVectors);
    mj["rim"] = mesh.rim;
  }
  return mj;
}

// The physical thin-film table over thickness x cos(theta), as JSON numbers or RGBA16F base64.
json thinFilmJson(const json& body, const bb::Params& params, const json& tf, const json& range,
                  const RequestContext& ctx, effects::Stats& stats) {
  const bb::ThinFilmOptions o = thinFilmOptions(body, params, ctx.config, ctx.at);
  auto r = bb::thinFilmTable(o);
  if (!r.ok()) {
    effects::Error e = r.error();
    throwError(e, ctx.at + "/thinFilm");
  }
  const bb::ThinFilmTable& table = r.value();
  json j = {{"width", table.width},
            {"height", table.height},
            {"axes", "u: thickness from thicknessRange[0] (column 0) to [1] nm; v: cos(theta) from 0 (row 0) to 1"},
            {"thicknessRange", range},
            {"wavelengths", o.wavelengths},
            {"colorSpace", "linear sRGB, D65, reflectance of the film (white-balanced: R = 1 gives 1)"},
            {"meanDeltaE", table.meanDeltaE},
            {"maxDeltaE", table.maxDeltaE},
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

// `uniforms` (and eqn 9's flowOffset beside them) and `shader`, as `include` asks.
void addShaderParts(const json& body, const Includes& include, const bb::Params& params, const bb::Features& features,
                    double t, json& out) {
  // Both GLSL versions declare the same uniforms, so one variant serves uniforms and shader.
  const bool es = body.value("shader", json::object()).value("language", "glsl-es-300") == "glsl-es-300";
  bb::ShaderSource s;
  if (include.has("uniforms") || include.has("shader"))
    s = bb::shader(features, es ? bb::Glsl::kEs300 : bb::Glsl::kCore330);
  if (include.has("uniforms")) out["uniforms"] = uniforms(params, s.uniforms, t);
  if (include.has("uniforms") && features.textureFlow) {  // eqn 9, for clients that offset on the CPU
    const glm::dvec2 off = bb::flowOffset(params, t);
    out["flowOffset"] = {off.x, off.y};
  }
  if (include.has("shader")) {
    out["shader"] = {
        {"language", es ? "glsl-es-300" : "glsl-330"},
        {"vertex", s.vertex},
        {"fragment", s.fragment},
        {"uniforms", s.uniforms},
        {"attributes", features.textureFlow ? json{"aPosition", "aNormal", "aUv"} : json{"aPosition", "aNormal"}}};
  }
}

}  // namespace

JsonReply handleBubble(const json& body, const RequestContext& ctx) {
  Includes include(body, kBubbleIncludes);
  const bb::Params params = parseBubbleParams(body.value("params", json::object()), ctx.at + "/params");
  const bb::Features features = parseBubbleFeatures(body.value("features", json::object()));
  const double t = body.value("time", 0.0);
  const json tf = body.value("thinFilm", json::object());
  const json range = tf.value("thicknessRange", json{0, 1000});
  // glTF's default range is 100-400 nm; a request's thicknessRange overrides it.
  const bool rangeGiven = tf.contains("thicknessRange");
  const double gltfMin = rangeGiven ? range[0].get<double>() : 100.0;
  const double gltfMax = rangeGiven ? range[1].get<double>() : 400.0;
  JsonReply reply;
  reply.method = "seed000";
  if (body.value("format", "json") == "glb") {  // the whole bubble as one file instead of JSON
    const bb::Mesh mesh = buildMesh(body, params, features, t, ctx);
    reply.computeMs = mesh.stats.elapsedMs;
    reply.binary = bubbleGlb(mesh, params, features, gltfMin, gltfMax);
    reply.contentType = "model/gltf-binary";
    return reply;
  }
  json out = {{"method", reply.method}};
  json stats = json::array();
  effects::Stopwatch watch;

  if (body.contains("motion")) {
    const json& m = body["motion"];
    glm::dvec3 c = bb::moveTowards(toVec3(m["from"]), toVec3(m["to"]), m["s"].get<double>());
    out["position"] = {c.x, c.y, c.z};
  }
  addShaderParts(body, include, params, features, t, out);
  reply.computeMs += watch.ms();
  if (include.has("mesh")) {
    bb::Mesh mesh = buildMesh(body, params, features, t, ctx);
    reply.computeMs += mesh.stats.elapsedMs;
    stats.push_back(statsJson(mesh.stats));
    out["mesh"] = meshJson(std::move(mesh), body.value("uvOrigin", "bottom-left") == "top-left");
  }
  if (include.has("thinFilm")) {
    effects::Stats st;
    out["thinFilm"] = thinFilmJson(body, params, tf, range, ctx, st);
    reply.computeMs += st.elapsedMs;
    stats.push_back(statsJson(st));
  }
  if (include.has("gltf")) {
    out["gltf"] = {{"KHR_materials_iridescence",
                    {{"iridescenceFactor", features.iridescence ? 1.0 : 0.0},
                     {"iridescenceIor", params.n2},
                     {"iridescenceThicknessMinimum", gltfMin},
                     {"iridescenceThicknessMaximum", gltfMax}}}};
  }
  if (include.has("stats")) out["stats"] = std::move(stats);
  reply.body = std::move(out);
  return reply;
}

void addBubbleEndpoints(Service& service) {
  service.addJsonEndpoint("/v1/bubble", "bubble.json", handleBubble, bubbleCost);
}

}  // namespace effectd
