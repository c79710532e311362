// JSON scenes (proto/schemas/scene.json) -> render::Scene: each effect computed by its own
// endpoint's parsers, images decoded, what an animation needs (scene.h).
#include <map>
#include <memory>
#include <mutex>

#include <glm/geometric.hpp>

#include <effects/bubble.h>
#include <effects/glow.h>

#include "api/api_bubble.h"
#include "api/api_common.h"
#include "api/api_fog.h"
#include "api/api_lightning.h"
#include "contract/codec.h"
#include "api/scene.h"

namespace effectd {
namespace {

using nlohmann::json;
namespace rd = effects::render;
namespace bb = effects::bubble;

glm::dvec4 rgba(const json& j) {
  return {j[0].get<double>(), j[1].get<double>(), j[2].get<double>(), j.size() > 3 ? j[3].get<double>() : 1.0};
}

rd::Image image(const json& base64, const std::string& pointer, const Config& config) {
  auto bytes = base64Decode(base64.get<std::string>());
  if (!bytes) throw fieldError(400, pointer, "is not valid base64 (standard alphabet, padded)");
  auto decoded = rd::decodeImage(*bytes, config.limits.maxRenderPixels);
  if (!decoded.ok()) {
    effects::Error e = decoded.error();
    if (e.kind == effects::ErrorKind::kLimitExceeded) e.message += " (--max-render-pixels)";
    throwError(e, pointer);
  }
  return std::move(decoded.value());
}

// What renders share, deterministic in a key and costly to make (thin-film tables: tens of
// milliseconds; the sphere a bubble is drawn on: milliseconds, its normals through MikkTSpace's
// welding): kept process-wide, at most 16 of each (all dropped when full). make() runs outside
// the lock; two requests may both make a missing entry, and the first stored wins.
template <class T>
class SharedCache {
 public:
  template <class Make>
  std::shared_ptr<const T> get(const std::string& key, Make make) {
    {
      std::lock_guard<std::mutex> lock(mu_);
      if (auto it = entries_.find(key); it != entries_.end()) return it->second;
    }
    std::shared_ptr<const T> made = make();
    std::lock_guard<std::mutex> lock(mu_);
    if (auto it = entries_.find(key); it != entries_.end()) return it->second;  // stored meanwhile
    if (entries_.size() >= 16) entries_.clear();
    return entries_.emplace(key, std::move(made)).first->second;
  }

 private:
  std::mutex mu_;
  std::map<std::string, std::shared_ptr<const T>> entries_;
};

std::shared_ptr<const bb::ThinFilmTable> cachedThinFilm(const bb::ThinFilmOptions& o, const std::string& pointer) {
  static SharedCache<bb::ThinFilmTable> cache;
  const std::string key = json{o.ior, o.thicknessMinNm, o.thicknessMaxNm, o.width, o.height, o.wavelengths}.dump();
  return cache.get(key, [&] {
    auto table = bb::thinFilmTable(o);
    if (!table.ok()) throwError(table.error(), pointer + "/thinFilm");
    return std::make_shared<const bb::ThinFilmTable>(std::move(table.value()));
  });
}

// The still sphere the vertex shader wobbles: it depends on the level and radius alone.
std::shared_ptr<const bb::Mesh> cachedSphere(const bb::Params& p, const bb::MeshOptions& o, const std::string& at) {
  static SharedCache<bb::Mesh> cache;
  return cache.get(json{o.level, o.radius}.dump(), [&] {
    auto mesh = bb::icosphere(p, o);
    if (!mesh.ok()) throwError(mesh.error(), at, meshFields(at));
    return std::make_shared<const bb::Mesh>(std::move(mesh.value()));
  });
}

void parseCamera(const json& body, rd::Scene& s) {
  const json cam = body.value("camera", json::object());
  if (cam.contains("position")) s.camera.position = toVec3(cam["position"]);
  if (cam.contains("target")) s.camera.target = toVec3(cam["target"]);
  if (cam.contains("up")) s.camera.up = toVec3(cam["up"]);
  s.camera.fovYDeg = cam.value("fovY", s.camera.fovYDeg);
  s.camera.nearPlane = cam.value("near", s.camera.nearPlane);
  s.camera.farPlane = cam.value("far", s.camera.farPlane);
  const glm::dvec3 forward = s.camera.target - s.camera.position;
  if (glm::length(forward) < 1e-12) throw fieldError(400, "/camera/target", "must differ from the camera position");
  if (!(glm::length(glm::cross(forward, s.camera.up)) > 1e-12 * glm::length(forward) * glm::length(s.camera.up)))
    throw fieldError(400, "/camera/up", "must not be parallel to the view direction (or zero)");
  if (!(s.camera.farPlane > s.camera.nearPlane)) throw fieldError(400, "/camera/far", "must be greater than near");
}

void parseBackground(const json& b, const Config& config, rd::Scene& s) {
  if (b.contains("color")) s.background.color = rgba(b["color"]);
  if (b.contains("gradient")) {
    s.background.kind = rd::Background::Kind::kGradient;
    s.background.top = rgba(b["gradient"]["top"]);
    s.background.bottom = rgba(b["gradient"]["bottom"]);
  }
  if (b.contains("image")) {
    s.background.kind = rd::Background::Kind::kImage;
    s.background.image = image(b["image"], "/background/image", config);
  }
}

rd::SurfaceWave parseSurfaceWave(const json& w, size_t quads) {
  rd::SurfaceWave wave;
  if (w.contains("quad")) {
    wave.onQuad = w["quad"].get<size_t>();
    if (*wave.onQuad >= quads)
      throw fieldError(422, "/surfaceWave/quad",
                       "names quad " + std::to_string(*wave.onQuad) + " but the scene has " + std::to_string(quads));
  }
  wave.strength = w.value("strength", wave.strength);
  wave.scale = w.value("scale", wave.scale);
  wave.speed = w.value("speed", wave.speed);
  if (w.contains("lightColor")) wave.lightColor = toVec3(w["lightColor"]);
  if (w.contains("lightDirection")) wave.lightDirection = toVec3(w["lightDirection"]);
  requireNonZero(wave.lightDirection, "/surfaceWave/lightDirection");
  return wave;
}

void parseQuads(const json& quads, rd::Scene& s) {
  for (size_t i = 0; i < quads.size(); ++i) {
    const json& q = quads[i];
    rd::Quad quad;
    quad.center = toVec3(q["center"]);
    if (q.contains("normal")) quad.normal = toVec3(q["normal"]);
    if (q.contains("up")) quad.up = toVec3(q["up"]);
    requireNonZero(quad.normal, "/quads/" + std::to_string(i) + "/normal");
    quad.size = {q["size"][0].get<double>(), q["size"][1].get<double>()};
    if (q.contains("color")) quad.color = toVec3(q["color"]);
    s.quads.push_back(quad);
  }
}

// The scene's "/fog", as /v1/fog's parser read it.
rd::Fog sceneFog(const FogRequest& f) {
  if (f.regions.size() > rd::kMaxFogRegions)
    throw fieldError(422, "/fog/regions",
                     "a rendered scene takes at most " + std::to_string(rd::kMaxFogRegions) + " fog regions");
  return {f.fog, f.regions};
}

// The bolt grown as /v1/lightning grows it (r: its parser's), in the scene's style; for an
// animated render, its strike timeline.
rd::Lightning sceneLightning(const LightningRequest& r, const json& body, Animation* animation,
                             const JobProgress& progress) {
  const effects::lightning::Bolt bolt = growBolt(boltParams(r, "/lightning"), "/lightning", progress);
  rd::Lightning l;
  l.polylines = effects::lightning::polylines(bolt, r.shape);
  if (r.params.depth) {  // a 3-D bolt lies in the scene: its vertices in world units
    World world = r.world;
    world.given = true;  // without "world": origin 0, one unit per voxel
    for (auto& line : l.polylines)
      for (auto& v : line.vertices) {
        const auto p = world.toWorld(v.x, v.y, v.z);
        v.x = float(p[0]), v.y = float(p[1]), v.z = float(p[2]);
      }
    l.world = true;
  }
  if (animation && animation->frames.count > 0) {
    animation->bolt = l.polylines;
    auto strike = effects::lightning::timeline(bolt, l.polylines, r.timeline);
    if (!strike.ok()) throwError(strike.error(), "/lightning");
    animation->strike = std::move(strike.value());
    animation->strikeTime = body.value("lightningStyle", json::object()).value("strikeTime", animation->time);
  }
  l.gridWidth = r.params.width;
  l.gridHeight = r.params.height;
  const json st = body.value("lightningStyle", json::object());
  if (st.contains("rect")) {
    const json& r = st["rect"];
    l.rect = {r[0].get<double>(), r[1].get<double>(), r[2].get<double>(), r[3].get<double>()};
  }
  if (st.contains("color")) l.color = toVec3(st["color"]);
  l.coreWidth = st.value("coreWidth", l.coreWidth);
  l.glowSigma = st.value("glowSigma", l.glowSigma);
  l.glowStrength = st.value("glowStrength", l.glowStrength);
  l.radiance = st.value("radiance", l.radiance);
  if (st.contains("forwardScattering")) l.forwardScattering = st["forwardScattering"].get<double>();
  l.apsfMethod = *effects::glow::methodFromString(st.value("glowKernel", "gaussians-3"));  // enum checked by the schema
  return l;
}

// A bubble as /v1/bubble's parser read it, its body and style where the parser found them:
// mesh and thin-film table computed once here, wobbled by the shader.
rd::Bubble sceneBubble(const SceneBubble& part, const json& body, const RequestContext& ctx, double sceneTime) {
  const Config& config = ctx.config;
  const BubbleRequest& r = part.request;
  const std::string& at = part.at;
  const json& bj = body[json::json_pointer(at)];
  const json::json_pointer styleAt(part.styleAt);
  const json style = body.contains(styleAt) ? body[styleAt] : json::object();
  rd::Bubble b;
  const double t = r.time.value_or(sceneTime);
  b.params = r.params;
  b.features = r.features;
  const bool film = b.features.shading == bb::Shading::kFilm;
  bb::MeshOptions o;
  o.level = r.meshLevelGiven ? r.mesh.level : kRenderedIcosphereLevel;
  o.maxLevel = kMaxIcosphereLevel;
  o.radius = r.mesh.radius;
  o.wobble = false;  // the vertex shader wobbles (eqn 11)
  o.parallel = ctx.parallel;
  if (auto e = bb::validate(b.params)) throwError(*e, at);  // the cached sphere's were other params
  b.mesh = cachedSphere(b.params, o, at);
  if (b.features.wobble)  // the shader wobbles what icosphere() left still
    if (auto e = bb::wobbleFits(b.params, o.radius)) throwError(*e, at + "/mesh");
  b.radius = o.radius;
  if (film) {
    b.film = r.film;
    b.lights = r.lights;
  }
  if (film || b.features.iridescence) {
    bb::ThinFilmOptions tf = r.thinFilm;
    checkThinFilmSize(tf, config, at);
    tf.measureError = false;
    b.thinFilm = cachedThinFilm(tf, at);
    b.thinFilmRangeNm = {tf.thicknessMinNm, tf.thicknessMaxNm};
  }
  if (bj.contains("motion")) {
    const json& mo = bj["motion"];
    b.center = bb::moveTowards(toVec3(mo["from"]), toVec3(mo["to"]), mo["s"].get<double>());
  }
  if (style.contains("center") && !bj.contains("motion")) b.center = toVec3(style["center"]);
  if (style.contains("baseColor")) b.baseColor = rgba(style["baseColor"]);
  if (style.contains("flowTexture")) b.flowTexture = image(style["flowTexture"], part.styleAt + "/flowTexture", config);
  b.time = t;
  if (auto e = rd::prepareThickness(b, ctx.parallel)) throwError(*e, at);
  return b;
}

// "frames": how many, how fast, and into what; frames x pixels within --max-render-pixels.
Frames parseFrames(const json& f, int count, const rd::Scene& s, const Config& config) {
  Frames out;
  out.count = count;
  out.fps = f.value("fps", out.fps);
  out.flipbook = f.value("format", "gif") == "flipbook";
  if (!out.flipbook && out.fps > 50)
    throw fieldError(422, "/frames/fps", "a GIF plays at most 50 frames per second (delays are whole hundredths "
                                         "of a second, at least 2); use a flipbook for faster rates");
  // A flipbook's sheet holds whole rows: its unused cells are pixels too.
  const size_t cells = out.flipbook ? size_t(rd::Flipbook::cells(out.count)) : size_t(out.count);
  const size_t pixels = cells * size_t(s.width) * size_t(s.height);
  if (pixels > config.limits.maxRenderPixels)
    throw fieldError(413, "/frames/count",
                     std::to_string(out.count) + " frames of " + std::to_string(s.width) + "x" +
                         std::to_string(s.height) + " are " + std::to_string(pixels) + " pixels, over the limit of " +
                         std::to_string(config.limits.maxRenderPixels) + " (--max-render-pixels)");
  return out;
}

}  // namespace

rd::Scene buildScene(const RenderRequest& request, const json& body, const RequestContext& ctx, double* computeMs,
                     Animation* animation) {
  const SceneRequest& parts = request.scene;
  const Config& config = ctx.config;
  effects::Stopwatch watch;
  rd::Scene s;
  s.width = request.width;  // as parseRenderRequest read them
  s.height = request.height;
  if (size_t(s.width) * size_t(s.height) > config.limits.maxRenderPixels)
    throw fieldError(413, "/width",
                     std::to_string(s.width) + "x" + std::to_string(s.height) + " exceeds the limit of " +
                         std::to_string(config.limits.maxRenderPixels) + " pixels (--max-render-pixels)");
  s.bitDepth = body.value("bitDepth", 8);
  s.time = body.value("time", 0.0);
  if (animation) {
    animation->time = s.time;
    if (request.frames) animation->frames = parseFrames(body["frames"], *request.frames, s, config);
  }
  parseCamera(body, s);
  if (body.contains("background")) parseBackground(body["background"], config, s);
  if (body.contains("environment")) {
    const json& e = body["environment"];
    rd::Environment env;
    if (e.contains("zenith")) env.zenith = toVec3(e["zenith"]);
    if (e.contains("horizon")) env.horizon = toVec3(e["horizon"]);
    if (e.contains("ground")) env.ground = toVec3(e["ground"]);
    s.environment = env;
  }
  if (body.contains("cameraBlend"))
    s.blend = rd::CameraBlend{toVec3(body["cameraBlend"]["color"]), body["cameraBlend"]["amount"].get<double>()};
  if (body.contains("quads")) parseQuads(body["quads"], s);
  if (body.contains("surfaceWave")) s.wave = parseSurfaceWave(body["surfaceWave"], s.quads.size());
  if (parts.fog) s.fog = sceneFog(*parts.fog);
  if (parts.lightning) s.lightning = sceneLightning(*parts.lightning, body, animation, ctx.progress);
  for (const SceneBubble& b : parts.bubbles) s.bubbles.push_back(sceneBubble(b, body, ctx, s.time));
  if (animation)
    for (const rd::Bubble& b : s.bubbles) animation->bubbleTimes.push_back(b.time);
  if (computeMs) *computeMs = watch.ms();
  return s;
}

}  // namespace effectd
