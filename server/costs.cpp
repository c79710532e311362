#include "costs.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "api_bubble.h"
#include "api_common.h"
#include "api_fog.h"
#include "api_lightning.h"
#include "api_tangents.h"
#include "effects/lightning.h"

namespace effectd {

using nlohmann::json;

namespace {

// A number in an answer: the JSON value in its array (16 B, vectors up to 2x their size),
// its text, and the encoded copy.
constexpr size_t kAnswerNumber = 56;
constexpr size_t kBase = 256u << 10;  // any request: handler scratch, headers, strings
// Work above these sizes takes long enough to hold a core: it is heavy.
constexpr size_t kHeavyGridCells = 1024u * 1024u;
constexpr size_t kHeavyTriangles = 200'000;
constexpr int kHeavyLevel = 6;

}  // namespace

Cost fogCost(const json& body, const Config& config) {
  const json table = body.value("table", json::object());
  size_t size = table.contains("maxError") ? config.limits.maxTableSize : table.value("size", size_t(256));
  const bool height = body.value("fog", json::object()).value("fogType", "") == "HEIGHT";
  size_t entries = height ? size * table.value("elevations", size) : size;
  entries = std::min(entries, config.limits.maxTableSize);
  const size_t colors = body.contains("objectColors") ? body["objectColors"].size() : 0;
  const size_t samples = body.contains("samples") ? body["samples"].value("points", json::array()).size() : 0;
  return {kBase + entries * (64 + kAnswerNumber * (4 + 3 * colors)) + samples * 8 * kAnswerNumber, false};
}

Cost lightningCost(const json& body, const Config& config) {
  // Sizes over a configured limit are refused by the handler naming the field: clamp here.
  const std::string method = body.value("method", "fast");
  const bool solver = method != "fast";
  const size_t depth = size_t(body["grid"].value("depth", 0));
  const size_t cells =
      std::min(size_t(body["grid"]["width"].get<int>()) * size_t(body["grid"]["height"].get<int>()) * std::max<size_t>(depth, 1),
               solver ? (depth ? config.limits.maxSolverVolumeCells : config.limits.maxSolverGridCells)
                      : config.limits.maxGridCells);
  // Working set per cell: fast keeps the obstacle grid, candidate and potential state and
  // the boundary map; dbm keeps the multigrid hierarchy (fields, Galerkin stencils: 27-point
  // ones in 3-D). 3-D fast keeps its per-voxel state in pages of the voxels the bolt and the
  // A* search touch (effects/lightning/grid.h: CellMap): at worst (a search that floods the
  // volume) A*'s cost and parent (8 bytes), the obstacle and octree charge bytes.
  // dbm also keeps DeepField's per-cell state (effects/lightning/deep_field.h): a byte for the
  // cells fixed at 0, and once a stage is cut its stage number and frozen value (10 bytes).
  const size_t perCell = (solver ? (depth ? 200 : 160) : (depth ? 12 : 24)) + (method == "dbm" ? 11 : 0);
  // dbm's default capacitance solver adds its Cholesky factor, rows and table.
  const bool capacitance = method == "dbm" && body.value("solver", "capacitance") == "capacitance";
  const int width = body["grid"]["width"].get<int>(), height = body["grid"]["height"].get<int>();
  const bool clamped = size_t(width) * size_t(height) > cells;  // refused by the handler
  const int side = int(std::sqrt(double(cells)));
  const size_t direct =
      !capacitance ? 0
      : depth      ? effects::lightning::capacitanceBytes(width, height, int(depth))
                   : effects::lightning::capacitanceBytes(clamped ? side : width, clamped ? side : height);
  // The bolt: at most maxSteps cells, and in practice far fewer than the grid.
  const size_t steps =
      std::min<size_t>(body.value("maxSteps", config.limits.maxGrowthSteps), config.limits.maxGrowthSteps);
  const size_t boltCells = std::min({cells, steps, 16 * size_t(std::sqrt(double(cells))) + 4096});
  const Includes include(body, kLightningIncludes);
  size_t numbersPerCell = 0;
  if (include.has("polylines")) numbersPerCell += 5;
  if (include.has("cells")) numbersPerCell += 2;
  if (include.has("tree")) numbersPerCell += 3;
  return {kBase + cells * perCell + direct + boltCells * (96 + numbersPerCell * kAnswerNumber),
          solver || cells >= kHeavyGridCells};
}

Cost tangentsCost(const json& body, const Config& config) {
  const json& m = body["mesh"];
  const size_t vertices = std::min(m["positions"].size() / 3, config.limits.maxMeshVertices);
  const size_t triangles = std::min(m["indices"].size() / 3, config.limits.maxMeshTriangles);
  // Welding, adjacency and the MikkTSpace groups per corner, frames per vertex (the output
  // may have up to twice the vertices after splits); the answer as JSON numbers.
  const Includes include(body, kTangentsIncludes);
  size_t numbers = 0;
  if (include.has("tangents")) numbers += 2 * vertices * 4;
  if (include.has("remap")) numbers += 2 * vertices;
  if (include.has("indices")) numbers += 3 * triangles;
  if (include.has("normals")) numbers += 2 * vertices * 3;
  if (include.has("triangleFrames")) numbers += 11 * triangles;
  return {kBase + triangles * 3 * 64 + vertices * 2 * 64 + numbers * kAnswerNumber, triangles >= kHeavyTriangles};
}

Cost glbCost(const std::string& body, const Config&) {
  // The model's buffers decoded, the working set, and a new GLB with a tangent accessor:
  // bounded by a multiple of the file.
  return {kBase + body.size() * 12, body.size() >= (8u << 20)};
}

Cost bubbleCost(const json& body, const Config& config) {
  const Includes include(body, kBubbleIncludes);
  Cost c{kBase, false};
  const bool glb = body.value("format", "json") == "glb";  // the mesh, as a file
  if (include.has("mesh") || glb) {
    const int level = std::min(body.value("mesh", json::object()).value("level", 3), 7);
    const size_t vertices = 10 * (size_t(1) << (2 * level)) + 2, triangles = 20 * (size_t(1) << (2 * level));
    const size_t perVertex = body.contains("camera") ? 16 : 12;  // + final vectors and rim
    c.bytes += vertices * (64 + perVertex * kAnswerNumber) + triangles * (16 + 3 * kAnswerNumber);
    c.heavy = level >= kHeavyLevel;
  }
  if (include.has("thinFilm") && !glb) {
    const json tf = body.value("thinFilm", json::object());
    const size_t texels =
        std::min(size_t(tf.value("width", 256)) * size_t(tf.value("height", 256)), config.limits.maxThinFilmTexels);
    c.bytes += texels * (24 + 3 * kAnswerNumber + 8);  // float RGB, its numbers, or RGBA16F base64
  }
  if (include.has("thickness") || glb) {
    const json f = body.value("film", json::object());
    const effects::bubble::ThicknessOptions d;
    const size_t texels = std::min(size_t(f.value("width", d.width)) * size_t(f.value("height", d.height)),
                                   config.limits.maxThinFilmTexels);
    c.bytes += texels * (4 + kAnswerNumber + 16);  // floats, their numbers or base64, a 16-bit PNG
  }
  return c;
}

Cost sceneCost(const json& body, const Config& config) {
  Cost c{kBase, false};
  if (body.contains("lightning")) c += lightningCost(body["lightning"], config);
  if (body.contains("fog")) c += fogCost(body["fog"], config);
  if (body.contains("bubble")) c += bubbleCost(body["bubble"], config);
  if (body.contains("bubbles"))
    for (const json& item : body["bubbles"]) c += bubbleCost(item.value("bubble", json::object()), config);
  return c;
}

Cost renderCost(const json& body, const Config& config) {
  Cost c = sceneCost(body, config);
  c.heavy = c.heavy || body.value("reference", false);  // seconds of CPU ray tracing
  const size_t pixels =
      std::min(size_t(body.value("width", 512)) * size_t(body.value("height", 512)), config.limits.maxRenderPixels);
  // Render targets and read-back (RGBA float), the converted 8/16-bit image, the PNG; a
  // decoded background image.
  c.bytes += pixels * 96;
  // Frames: a flipbook sheet (RGBA float, then 8/16-bit and PNG) of count x pixels; a GIF
  // holds at most 9 RGBA8 frames (a batch being encoded and the one before) plus its output
  // (under a byte per pixel per frame).
  if (body.contains("frames")) {
    const size_t count = std::max<size_t>(1, body["frames"].value("count", 1));
    c.bytes += std::min(count * pixels, config.limits.maxRenderPixels) * 28;
  }
  if (body.contains("background") && body["background"].contains("image"))
    c.bytes += config.limits.maxRenderPixels * 16;
  c.heavy = c.heavy || pixels >= (2048u * 2048u);
  // Each bubble's thin-film table (float RGB, then 16F on the GPU) and, for the film, its
  // thickness texture rebuilt every frame on the render thread (~1 us per texel).
  std::vector<json> bubbles;
  if (body.contains("bubble")) bubbles.push_back(body["bubble"]);
  if (body.contains("bubbles"))
    for (const json& item : body["bubbles"]) bubbles.push_back(item.value("bubble", json::object()));
  const size_t frames = body.contains("frames") ? std::max<size_t>(1, body["frames"].value("count", 1)) : 1;
  size_t thicknessWork = 0;
  for (const json& b : bubbles) {
    const json tf = b.value("thinFilm", json::object());
    c.bytes += std::min(size_t(tf.value("width", 256)) * size_t(tf.value("height", 256)), config.limits.maxThinFilmTexels) * 18;
    if (b.value("shading", "film") != "film") continue;
    const json f = b.value("film", json::object());
    const effects::bubble::ThicknessOptions d;
    const size_t texels = std::min(size_t(f.value("width", d.width)) * size_t(f.value("height", d.height)),
                                   config.limits.maxThinFilmTexels);
    c.bytes += texels * 8;
    thicknessWork += texels * frames;
  }
  c.heavy = c.heavy || thicknessWork >= (size_t(1) << 22);  // seconds of thickness tracing
  return c;
}

}  // namespace effectd
