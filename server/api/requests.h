// The endpoints' typed requests: a body read and checked into one of these is the first of an
// endpoint's two steps (http/service.h, twoSteps). Its cost (costs.h) is estimated from it, and
// the run step answers from it; the body itself is kept only for what shapes the answer.
// Each field's default is applied where the body is read (the endpoint's parse function).
#pragma once

#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>
#include <nlohmann/json.hpp>

#include <effects/bubble.h>
#include <effects/fog.h>
#include <effects/glow.h>
#include <effects/lightning.h>
#include <effects/tangents.h>

#include "api/lightning_volume.h"

namespace effectd {

// The body's "include" list as a set test; `defaults` applies when "include" is absent.
class Includes {
 public:
  Includes(const nlohmann::json& body, std::vector<std::string> defaults);
  bool has(const std::string& what) const;

 private:
  std::vector<std::string> items_;
};

// What each endpoint answers when the body has no "include" list.
inline const std::vector<std::string> kFogIncludes = {"table"};
inline const std::vector<std::string> kLightningIncludes = {"polylines"};
inline const std::vector<std::string> kTangentsIncludes = {"tangents", "remap", "indices"};
inline const std::vector<std::string> kBubbleIncludes = {"uniforms", "shader"};

struct FogRequest {
  Includes include{nlohmann::json::object(), kFogIncludes};
  effects::fog::Fog fog;
  std::vector<effects::fog::Region> regions;
  effects::fog::TableOptions table;  // maxSize: the configured limit
  std::string encoding = "json";     // table.encoding: json, rgba8 or rgba16f
  std::optional<std::vector<glm::dvec3>> objectColors;  // the table's final colours are also given for these
  struct Samples {
    glm::dvec3 camera{0};
    std::vector<glm::dvec3> points;
  };
  std::optional<Samples> samples;  // exact fog at points seen from a camera
  std::string shaderLanguage = "glsl-es-300";  // include "shader": shader.language
  glm::dvec3 shaderCamera{0};                  // ... and the camera its uniforms are for
  struct Glow {  // include "glow": the APSF of this fog between a camera and a light
    std::optional<glm::dvec3> camera, source;  // T along this ray through the fog (and regions) ...
    std::optional<double> opticalThickness;    // ... or given
    std::optional<double> forwardScattering;   // q; none: the fog's own at the source
    effects::glow::KernelOptions kernel;
  };
  std::optional<Glow> glow;
};

struct LightningRequest {
  Includes include{nlohmann::json::object(), kLightningIncludes};
  bool glb = false;                    // "format": "glb"
  std::string variant = "calibrated";  // or "paper"
  effects::lightning::Params params;   // obstacles, region, calibration: added by the run step
  CellShapes obstacles, targetRegion;  // as given; the run step draws them into params
  std::optional<int> lifetime;         // the body's own, over the calibration's or the variant's
  std::optional<double> axisGrowth;
  effects::lightning::ShapeParams shape;
  effects::lightning::TimelineParams timeline;  // animationSeed, timeScale, "timeline"
  World world;                                  // 3-D: where the grid lies ("world")
};

struct TangentsRequest {
  Includes include{nlohmann::json::object(), kTangentsIncludes};
  effects::tangents::Mesh mesh;
  effects::tangents::Mode mode = effects::tangents::Mode::kMikkTSpace;
};

struct BubbleRequest {
  Includes include{nlohmann::json::object(), kBubbleIncludes};
  bool glb = false;  // "format": "glb"
  effects::bubble::Params params;
  effects::bubble::Features features;
  effects::bubble::ThicknessOptions film;
  std::vector<effects::bubble::Light> lights;
  effects::bubble::MeshOptions mesh;  // level, radius, camera; the rest is set when it is built
  bool meshLevelGiven = false;        // else a rendered bubble's own default level
  std::optional<double> time;         // seconds; absent: 0, or a scene's time
  nlohmann::json thicknessRange;  // the thin-film table's axis, nm
  bool thicknessRangeGiven = false;  // thinFilm.thicknessRange was in the body
  effects::bubble::ThinFilmOptions thinFilm;
  std::string shaderLanguage = "glsl-es-300";
  struct Motion {
    glm::dvec3 from{0.0}, to{0.0};
    double s = 0;
  };
  std::optional<Motion> motion;  // the bubble carried by the air (seed 000 eqn 10)
};

// /v1/scene: the parts a scene has, each read by its endpoint's parser at its pointer.
// One of a scene's bubbles, and where the body holds it.
struct SceneBubble {
  BubbleRequest request;  // lit by the scene's lights when it has them
  std::string at;         // its body: "/bubble" or "/bubbles/<i>/bubble"
  std::string styleAt;    // its style: "/bubbleStyle" or "/bubbles/<i>"
};

struct SceneRequest {
  std::optional<LightningRequest> lightning;
  std::optional<FogRequest> fog;
  std::vector<SceneBubble> bubbles;  // "bubble", then each of "bubbles": the one order of them
};

// /v1/render: the scene's parts, and the frame.
struct RenderRequest {
  SceneRequest scene;
  bool reference = false;     // CPU ray tracing instead of the GPU
  bool measureError = false;  // the frame against the CPU reference (its bubble pass)
  int width = 0, height = 0;  // render::Scene's defaults unless given
  std::optional<int> frames;  // "frames.count"; none: a still
  bool backgroundImage = false;
};

}  // namespace effectd
