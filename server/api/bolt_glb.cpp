// The bolt's ribbons as one binary glTF 2.0 file (declared in bolt_ribbons.h).
#include <algorithm>
#include <cmath>

#include <render/render.h>

#include "api/bolt_ribbons.h"
#include "api/api_common.h"
#include "api/glb.h"

namespace effectd {
namespace {

using nlohmann::json;

// The channel's cross-section as a texture over v (rows; one column serves every u): white,
// alpha 1 over the middle third, falling smoothly to 0 at the edges, as the preview's core
// is solid with soft edges. 8-bit, 1 x 32.
std::string profilePng() {
  effects::render::Image image;
  image.width = 1;
  image.height = 32;
  image.rgba.assign(size_t(image.height) * 4, 1.0f);
  for (int y = 0; y < image.height; ++y) {
    const double v = (y + 0.5) / image.height, x = std::clamp(3.0 * (1.0 - std::abs(2.0 * v - 1.0)), 0.0, 1.0);
    image.rgba[size_t(y) * 4 + 3] = float(x * x * (3 - 2 * x));
  }
  auto png = effects::render::encodePng(image, 8);
  if (!png.ok()) throwError(png.error(), "");
  return std::move(png.value());
}

// glTF's colour factors are linear; effectd's frames hold display (sRGB-encoded) values.
double linearFromSrgb(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }


}  // namespace

std::string boltGlb(const std::array<Ribbons, 2>& ribbons, const std::array<double, 3>& display,
                    const json& timelineJson) {
  const std::array<double, 3> color = {linearFromSrgb(display[0]), linearFromSrgb(display[1]), linearFromSrgb(display[2])};
  glb::Asset a;
  a.gltf = json::object();
  a.gltf["asset"] = {{"version", "2.0"}, {"generator", "effectd /v1/lightning"}};
  a.gltf["accessors"] = json::array();
  a.gltf["bufferViews"] = json::array();
  a.gltf["meshes"] = json::array();
  a.gltf["nodes"] = json::array();
  json roots = json::array();
  for (const Ribbons& r : ribbons) {
    if (r.indices.empty()) continue;
    const int position = glb::addPositionAccessor(a, r.positions);
    std::vector<float> rgb;
    rgb.reserve(r.intensity.size() * 3);
    for (float i : r.intensity) rgb.insert(rgb.end(), {i, i, i});
    json attributes = {{"POSITION", position},
                       {"TEXCOORD_0", glb::addFloatAccessor(a, r.uvs, 2, true)},
                       {"COLOR_0", glb::addFloatAccessor(a, rgb, 3, true)}};
    if (!r.leader.empty()) {
      attributes["_LEADER"] = glb::addFloatAccessor(a, r.leader, 1, true);
      attributes["_STROKE_DELAY"] = glb::addFloatAccessor(a, r.strokeDelay, 1, true);
    }
    const json primitive = {{"attributes", attributes}, {"indices", glb::addIndexAccessor(a, r.indices)}, {"material", 0}};
    const std::string name = r.main ? "main" : "branches";
    a.gltf["meshes"].push_back({{"name", name}, {"primitives", json::array({primitive})}});
    roots.push_back(a.gltf["nodes"].size());
    a.gltf["nodes"].push_back({{"name", name}, {"mesh", a.gltf["meshes"].size() - 1}});
  }
  json scene = {{"name", "bolt"}, {"nodes", roots}};
  if (!timelineJson.is_null()) scene["extras"] = {{"timeline", timelineJson}};
  a.gltf["scene"] = 0;
  a.gltf["scenes"] = json::array({scene});
  const int image = glb::addPngImage(a, profilePng());
  // u runs along the channel in world units (repeat), v across it (clamp).
  a.gltf["samplers"] = json::array({json{{"magFilter", 9729}, {"minFilter", 9729}, {"wrapS", 10497}, {"wrapT", 33071}}});
  a.gltf["textures"] = json::array({json{{"source", image}, {"sampler", 0}}});
  const json rgb = json::array({color[0], color[1], color[2]});
  a.gltf["materials"] = json::array({json{
      {"name", "bolt (draw additively)"},
      {"doubleSided", true},
      {"alphaMode", "BLEND"},
      {"pbrMetallicRoughness",
       {{"baseColorFactor", {color[0], color[1], color[2], 1.0}},
        {"baseColorTexture", {{"index", 0}}},
        {"metallicFactor", 0.0},
        {"roughnessFactor", 1.0}}},
      {"emissiveFactor", rgb},
      {"emissiveTexture", {{"index", 0}}},
      {"extensions", {{"KHR_materials_unlit", json::object()}}}}});
  a.gltf["extensionsUsed"] = json::array({"KHR_materials_unlit"});
  return glb::serialize(a);
}

}  // namespace effectd
