#include "api/costs.h"

#include "api/api_render.h"

#include <algorithm>
#include <cmath>

#include "effects/lightning.h"

namespace effectd {

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

Cost fogCost(const FogRequest& r, const Config& config) {
  // With maxError the table grows until it meets the bound: at most the limit.
  const size_t size = r.table.maxError > 0 ? config.limits.maxTableSize : r.table.size;
  const bool height = r.fog.type == effects::fog::FogType::kHeight;
  size_t entries = height ? size * effects::fog::tableRows(r.table, size) : size;
  entries = std::min(entries, config.limits.maxTableSize);
  return {kBase + entries * (64 + kAnswerNumber * (4 + 3 * (r.objectColors ? r.objectColors->size() : 0))) +
             (r.samples ? r.samples->points.size() : 0) * 8 * kAnswerNumber +
             (r.glow ? size_t(r.glow->kernel.samples) * (8 * 4 + 2 * kAnswerNumber) : 0),  // the series at 4x samples
          false};
}

Cost lightningCost(const LightningRequest& r, const Config& config) {
  // Sizes over a configured limit are refused by the parser naming the field: clamped here all the same.
  namespace lt = effects::lightning;
  const lt::Params& p = r.params;
  const bool solver = p.method != lt::Method::kFast;
  const size_t depth = size_t(p.depth);
  const size_t cells = std::min(size_t(p.width) * size_t(p.height) * std::max<size_t>(depth, 1),
                                solver ? (depth ? config.limits.maxSolverVolumeCells : config.limits.maxSolverGridCells)
                                       : config.limits.maxGridCells);
  // Working set per cell: fast keeps the obstacle grid, candidate and potential state and
  // the boundary map; dbm keeps the multigrid hierarchy (fields, Galerkin stencils: 27-point
  // ones in 3-D). 3-D fast keeps its per-voxel state in pages of the voxels the bolt and the
  // A* search touch (effects/lightning/grid.h: CellMap): at worst (a search that floods the
  // volume) A*'s cost and parent (8 bytes), the obstacle and octree charge bytes.
  // dbm also keeps DeepField's per-cell state (effects/lightning/deep_field.h): a byte for the
  // cells fixed at 0, and once a stage is cut its stage number and frozen value (10 bytes).
  const bool dbm = p.method == lt::Method::kDbm;
  // A target region: three copies of its flags (the request's, the grower's, the A* guide's
  // for targets before it) and the k-d tree fast measures eqn 5's P with, 13 bytes per surface
  // cell; at most 6 of 7 cells lie on a region's surface (a 3-D packing that leaves every
  // region cell a free neighbour), so 3 + 13 * 6/7 < 15 bytes per cell.
  const size_t perCell =
      (solver ? (depth ? 200 : 160) : (depth ? 12 : 24)) + (dbm ? 11 : 0) + (r.targetRegion.given ? 15 : 0);
  // dbm's default capacitance solver adds its Cholesky factor, rows and table.
  const bool capacitance = dbm && p.solver == lt::Solver::kCapacitance;
  const bool clamped = size_t(p.width) * size_t(p.height) > cells;  // refused by the parser
  const int side = int(std::sqrt(double(cells)));
  const size_t direct = !capacitance ? 0
                        : depth      ? lt::capacitanceBytes(p.width, p.height, p.depth)
                                     : lt::capacitanceBytes(clamped ? side : p.width, clamped ? side : p.height);
  // The bolt: at most maxSteps cells, and in practice far fewer than the grid.
  const size_t boltCells = std::min({cells, p.maxSteps, 16 * size_t(std::sqrt(double(cells))) + 4096});
  size_t numbersPerCell = 0;
  if (r.include.has("polylines")) numbersPerCell += 5;
  if (r.include.has("cells")) numbersPerCell += 2;
  if (r.include.has("tree")) numbersPerCell += 3;
  return {kBase + cells * perCell + direct + boltCells * (96 + numbersPerCell * kAnswerNumber),
          solver || cells >= kHeavyGridCells};
}

Cost tangentsCost(const TangentsRequest& r, const Config& config) {
  const size_t vertices = std::min(r.mesh.positions.size(), config.limits.maxMeshVertices);
  const size_t triangles = std::min(r.mesh.indices.size() / 3, config.limits.maxMeshTriangles);
  // Welding, adjacency and the MikkTSpace groups per corner, frames per vertex (the output
  // may have up to twice the vertices after splits); the answer as JSON numbers.
  size_t numbers = 0;
  if (r.include.has("tangents")) numbers += 2 * vertices * 4;
  if (r.include.has("remap")) numbers += 2 * vertices;
  if (r.include.has("indices")) numbers += 3 * triangles;
  if (r.include.has("normals")) numbers += 2 * vertices * 3;
  if (r.include.has("triangleFrames")) numbers += 11 * triangles;
  return {kBase + triangles * 3 * 64 + vertices * 2 * 64 + numbers * kAnswerNumber, triangles >= kHeavyTriangles};
}

Cost glbCost(const std::string& body, const Config&) {
  // The model's buffers decoded, the working set, and a new GLB with a tangent accessor:
  // bounded by a multiple of the file.
  return {kBase + body.size() * 12, body.size() >= (8u << 20)};
}

namespace {

size_t texels(int width, int height, const Config& config) {
  return std::min(size_t(width) * size_t(height), config.limits.maxThinFilmTexels);
}

}  // namespace

Cost bubbleCost(const BubbleRequest& r, const Config& config) {
  Cost c{kBase, false};
  if (r.include.has("mesh") || r.glb) {  // a GLB is the mesh, as a file
    const int level = std::min(r.mesh.level, r.mesh.maxLevel);
    const size_t vertices = 10 * (size_t(1) << (2 * level)) + 2, triangles = 20 * (size_t(1) << (2 * level));
    const size_t perVertex = r.mesh.camera ? 16 : 12;  // + final vectors and rim
    c.bytes += vertices * (64 + perVertex * kAnswerNumber) + triangles * (16 + 3 * kAnswerNumber);
    c.heavy = level >= kHeavyLevel;
  }
  if (r.include.has("thinFilm") && !r.glb)  // float RGB, its numbers, or RGBA16F base64
    c.bytes += texels(r.thinFilm.width, r.thinFilm.height, config) * (24 + 3 * kAnswerNumber + 8);
  if (r.include.has("thickness") || r.glb)  // floats, their numbers or base64, a 16-bit PNG
    c.bytes += texels(r.film.width, r.film.height, config) * (4 + kAnswerNumber + 16);
  return c;
}

Cost sceneCost(const SceneRequest& r, const Config& config) {
  Cost c{kBase, false};
  if (r.lightning) c += lightningCost(*r.lightning, config);
  if (r.fog) c += fogCost(*r.fog, config);
  for (const SceneBubble& b : r.bubbles) c += bubbleCost(b.request, config);
  return c;
}

Cost renderCost(const RenderRequest& r, const Config& config) {
  Cost c = sceneCost(r.scene, config);
  c.heavy = c.heavy || r.reference || r.measureError;  // seconds of CPU ray tracing
  if (r.measureError) c.bytes += std::min(size_t(r.width) * size_t(r.height), kMaxReferencePixels) * 17;
  const size_t pixels = std::min(size_t(r.width) * size_t(r.height), config.limits.maxRenderPixels);
  // Render targets and read-back (RGBA float), the converted 8/16-bit image, the PNG; a
  // decoded background image.
  c.bytes += pixels * 96;
  // Frames: a flipbook sheet (RGBA float, then 8/16-bit and PNG) of count x pixels; a GIF
  // holds at most 9 RGBA8 frames (a batch being encoded and the one before) plus its output
  // (under a byte per pixel per frame).
  const size_t frames = r.frames ? size_t(std::max(1, *r.frames)) : 1;
  if (r.frames) c.bytes += std::min(frames * pixels, config.limits.maxRenderPixels) * 28;
  if (r.backgroundImage) c.bytes += config.limits.maxRenderPixels * 16;
  c.heavy = c.heavy || pixels >= (2048u * 2048u);
  // Each bubble's thin-film table (float RGB, then 16F on the GPU) and, for the film, its
  // thickness texture rebuilt every frame on the render thread (~1 us per texel).
  size_t thicknessWork = 0;
  for (const SceneBubble& part : r.scene.bubbles) {
    const BubbleRequest& b = part.request;
    c.bytes += texels(b.thinFilm.width, b.thinFilm.height, config) * 18;
    if (b.features.shading != effects::bubble::Shading::kFilm) continue;
    const size_t film = texels(b.film.width, b.film.height, config);
    c.bytes += film * 8;
    thicknessWork += film * frames;
  }
  c.heavy = c.heavy || thicknessWork >= (size_t(1) << 22);  // seconds of thickness tracing
  return c;
}

}  // namespace effectd
