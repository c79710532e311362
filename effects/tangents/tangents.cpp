// Tangent frames: seed 004's per-triangle TBN and MikkTSpace (see effects/tangents.h): the
// order of the steps (steps.h), the statistics and the error against MikkTSpace.
#include "effects/tangents.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "../util/check.h"
#include "steps.h"

namespace effects::tangents {
namespace {

// Mean and worst angle between the corners' tangents and MikkTSpace's, and handedness flips.
void measureAgainstMikk(const Buffer<glm::vec4>& corner, const Buffer<glm::vec4>& mikk, Stats& st) {
  CHECK_EQ(corner.size(), mikk.size());
  double sum = 0, worst = 0;
  size_t flips = 0;
  for (size_t c = 0; c < corner.size(); ++c) {
    double a = angleDeg(corner[c], mikk[c]);
    sum += a;
    worst = std::max(worst, a);
    flips += corner[c].w != mikk[c].w;
  }
  st.error = sum / double(corner.size());
  st.errorMetric = "mean angle between corner tangents, degrees";
  st.reference = "mikktspace";
  st.counters["maxAngleDeg"] = worst;
  st.counters["handednessMismatches"] = double(flips);
}

}  // namespace

const char* toString(Mode mode) {
  switch (mode) {
    case Mode::kMikkTSpace: return "mikktspace";
    case Mode::kPerTriangle: return "perTriangle";
    case Mode::kPerVertex: return "perVertex";
  }
  return "?";
}

double angleDeg(const glm::vec4& a, const glm::vec4& b) {
  return cornerAngle(normalizeOrZero(dvec3(a)), normalizeOrZero(dvec3(b))) * 180.0 / 3.14159265358979323846;
}

std::optional<Error> validate(const Mesh& mesh, const Options& options) {
  const size_t n = mesh.positions.size();
  if (n > options.maxVertices)
    return overLimit("/positions",
                     std::to_string(n) + " vertices exceed the limit of " + std::to_string(options.maxVertices));
  if (mesh.indices.size() % 3 != 0) return invalid("/indices", "must hold three indices per triangle");
  if (mesh.indices.size() / 3 > options.maxTriangles)
    return overLimit("/indices", std::to_string(mesh.indices.size() / 3) + " triangles exceed the limit of " +
                                     std::to_string(options.maxTriangles));
  if (mesh.uvs.size() != n) return invalid("/uvs", "must hold one UV per vertex (" + std::to_string(n) + ")");
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    return invalid("/normals", "must be absent or hold one normal per vertex (" + std::to_string(n) + ")");
  auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  for (size_t i = 0; i < n; ++i) {
    if (!finite3(mesh.positions[i]))
      return invalid("/positions/" + std::to_string(i), "vertex " + std::to_string(i) + " is not finite");
    if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
      return invalid("/uvs/" + std::to_string(i), "UV " + std::to_string(i) + " is not finite");
    if (!mesh.normals.empty() && !finite3(mesh.normals[i]))
      return invalid("/normals/" + std::to_string(i), "normal " + std::to_string(i) + " is not finite");
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= n)
      return invalid("/indices/" + std::to_string(i), "index " + std::to_string(mesh.indices[i]) +
                                                          " is out of range (" + std::to_string(n) + " vertices)");
  return std::nullopt;
}

Result<Output> generate(const Mesh& meshIn, const Options& options) {
  if (auto e = validate(meshIn, options)) return *e;
  Stopwatch watch;
  // 1. Missing normals under the flat rule: every corner becomes its own vertex first.
  std::vector<uint32_t> cornerToInput;
  Mesh expanded;
  const bool flat = meshIn.normals.empty() && options.missingNormals == NormalRule::kFlat;
  if (flat) expanded = flatExpanded(meshIn, cornerToInput);
  const Mesh& mesh = flat ? expanded : meshIn;
  const size_t triCount = mesh.indices.size() / 3;
  // 2. A unit normal per vertex.
  size_t replacedNormals = 0;
  const std::vector<dvec3> normals = vertexNormals(mesh, options.parallel, replacedNormals);
  // 3. A tangent per corner by the requested method; MikkTSpace also when it is the reference.
  const bool needMikk = options.mode == Mode::kMikkTSpace || options.measureError;
  MikkStats mikkStats;
  CornerTangents mikk;
  Stopwatch referenceWatch;  // MikkTSpace as the reference only: the error's time, not the method's
  if (needMikk) mikk = mikktspace(mesh, normals, options.parallel, mikkStats);
  const double referenceMs = options.mode == Mode::kMikkTSpace ? 0.0 : referenceWatch.ms();
  CornerTangents corners = options.mode == Mode::kMikkTSpace  ? std::move(mikk)
                           : options.mode == Mode::kPerVertex ? perVertex(mesh, normals, options.parallel)
                                                              : perTriangle(mesh, normals, options.parallel);
  const size_t fallbacks = size_t(std::count(corners.fellBack.begin(), corners.fellBack.end(), uint8_t(1)));
  const double computeMs = watch.ms() - referenceMs;

  // 4. Vertices split where their corners disagree; normals follow the split.
  Output out;
  splitVertices(mesh, corners.tangent, normals, out);
  out.normals.resize(out.remap.size());
  for (size_t k = 0; k < out.remap.size(); ++k) out.normals[k] = glm::vec3(normals[out.remap[k]]);
  if (flat)
    for (uint32_t& r : out.remap) r = cornerToInput[r];
  if (options.triangleFrames) {
    out.triangleFrames.resize(triCount);
    for (size_t t = 0; t < triCount; ++t) out.triangleFrames[t] = faceFrame(mesh, t, normals);
  }

  // 5. Statistics, and the error against MikkTSpace for the other methods.
  Stats& st = out.stats;
  st.method = toString(options.mode);
  st.elapsedMs = computeMs;
  st.counters = {{"triangles", double(triCount)},
                 {"inputVertices", double(meshIn.positions.size())},
                 {"outputVertices", double(out.remap.size())},
                 {"fallbackCorners", double(fallbacks)},
                 {"replacedNormals", double(replacedNormals)}};  // zero-length: +z
  if (needMikk) {
    st.counters["degenerateTriangles"] = double(mikkStats.degenerateTriangles);
    st.counters["zeroUvAreaTriangles"] = double(mikkStats.zeroUvArea);
    st.counters["groups"] = double(mikkStats.groups);
  }
  if (meshIn.normals.empty()) st.counters["computedNormals"] = 1;
  if (options.mode != Mode::kMikkTSpace && options.measureError && !corners.tangent.empty()) {
    Stopwatch measuring;
    measureAgainstMikk(corners.tangent, mikk.tangent, st);
    st.errorMs = referenceMs + measuring.ms();
  }
  return out;
}

}  // namespace effects::tangents
