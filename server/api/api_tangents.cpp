// POST /v1/tangents — indexed triangle mesh (JSON) or binary glTF -> vertex tangents.
#include <cstdio>
#include <map>

#include <effects/tangents.h>

#include "api/api_common.h"
#include "api/api_tangents.h"
#include "api/costs.h"
#include "api/error_estimates.h"
#include "api/glb.h"

namespace effectd {
namespace {

using nlohmann::json;
namespace tg = effects::tangents;

tg::Options options(const RequestContext& ctx, tg::Mode mode) {
  const Config& config = ctx.config;
  tg::Options o;
  o.mode = mode;
  o.parallel = ctx.parallel;
  o.maxVertices = config.limits.maxMeshVertices;
  o.maxTriangles = config.limits.maxMeshTriangles;
  return o;
}

template <class V, int N>
std::vector<V> unflatten(const json& a, const std::string& pointer) {
  if (a.size() % N != 0) throw fieldError(400, pointer, "length must be a multiple of " + std::to_string(N));
  std::vector<V> out(a.size() / N);
  for (size_t i = 0; i < out.size(); ++i)
    for (int c = 0; c < N; ++c) out[i][c] = a[i * N + size_t(c)].get<float>();
  return out;
}

// Library fields name vertices; the wire has flat arrays ("/positions/7" -> "/mesh/positions/21").
const FieldTable kMeshFields = {
    {"positions", {"/mesh/positions", 3}}, {"normals", {"/mesh/normals", 3}}, {"uvs", {"/mesh/uvs", 2}}};

void flipW(tg::Output& out) {
  for (auto& t : out.tangents) t.w = -t.w;
}

}  // namespace

TangentsRequest parseTangentsRequest(const json& body, const RequestContext&) {
  TangentsRequest r;
  r.include = Includes(body, kTangentsIncludes);
  const json& m = body["mesh"];
  r.mesh.positions = unflatten<glm::vec3, 3>(m["positions"], "/mesh/positions");
  if (m.contains("normals")) r.mesh.normals = unflatten<glm::vec3, 3>(m["normals"], "/mesh/normals");
  r.mesh.uvs = unflatten<glm::vec2, 2>(m["uvs"], "/mesh/uvs");
  r.mesh.indices = m["indices"].get<std::vector<uint32_t>>();
  const std::string modeName = body.value("mode", "mikktspace");
  r.mode = modeName == "perTriangle" ? tg::Mode::kPerTriangle
           : modeName == "perVertex" ? tg::Mode::kPerVertex
                                     : tg::Mode::kMikkTSpace;
  return r;
}

JsonReply runTangents(const TangentsRequest& request, const json& body, const RequestContext& ctx) {
  const Includes& include = request.include;
  const tg::Mesh& mesh = request.mesh;
  tg::Options opt = options(ctx, request.mode);
  opt.measureError = include.has("error") && opt.mode != tg::Mode::kMikkTSpace;
  opt.triangleFrames = include.has("triangleFrames");
  auto r = tg::generate(mesh, opt);
  if (!r.ok()) throwError(r.error(), "/mesh", kMeshFields);
  tg::Output& out = r.value();
  if (body.value("uvOrigin", "bottom-left") == "top-left") flipW(out);

  JsonReply reply;
  reply.method = out.stats.method;
  reply.computeMs = out.stats.elapsedMs;
  reply.errorMs = out.stats.errorMs;
  {  // X-Effect-Error: the mean angle from MikkTSpace's tangents, measured, exact, or the report's
    const ErrorEstimate e = tangentsErrorEstimate(opt.mode);
    char h[256];
    if (out.stats.error)
      std::snprintf(h, sizeof h, "meanAngleDeg=%.4g; limit=%g; kind=measured; reference=\"MikkTSpace\"", *out.stats.error,
                    e.limit);
    else if (opt.mode == tg::Mode::kMikkTSpace)
      std::snprintf(h, sizeof h, "meanAngleDeg=0; kind=exact; reference=\"MikkTSpace (this is it)\"");
    else
      std::snprintf(h, sizeof h,
                    "meanAngleDeg=%.3g; limit=%g; kind=estimate; row=\"%s\"; reference=\"MikkTSpace on the error "
                    "report's meshes (the worse of two); include error measures this mesh\"",
                    e.value, e.limit, e.row.c_str());
    reply.headers["X-Effect-Error"] = h;
  }
  json res = {{"method", reply.method}, {"vertexCount", out.remap.size()}};
  if (include.has("tangents")) res["tangents"] = flat<4>(out.tangents);
  if (include.has("remap")) res["remap"] = out.remap;
  if (include.has("indices")) res["indices"] = out.indices;
  if (include.has("normals")) res["normals"] = flat<3>(out.normals);
  if (include.has("triangleFrames")) {
    json t = json::array(), b = json::array(), n = json::array(), w = json::array(), degenerate = json::array();
    for (size_t i = 0; i < out.triangleFrames.size(); ++i) {
      const tg::Frame& f = out.triangleFrames[i];
      for (int c = 0; c < 3; ++c) t.push_back(f.tangent[c]), b.push_back(f.bitangent[c]), n.push_back(f.normal[c]);
      w.push_back(f.w);
      if (f.degenerate) degenerate.push_back(i);
    }
    res["triangleFrames"] = {{"tangents", t}, {"bitangents", b}, {"normals", n}, {"w", w}, {"degenerate", degenerate}};
  }
  if (include.has("error")) {
    if (out.stats.error)
      res["error"] = {{"meanAngleDeg", *out.stats.error},
                      {"maxAngleDeg", out.stats.counters["maxAngleDeg"]},
                      {"handednessMismatches", out.stats.counters["handednessMismatches"]},
                      {"kind", "measured"},
                      {"metric", out.stats.errorMetric},
                      {"reference", out.stats.reference}};
    else
      res["error"] = {{"meanAngleDeg", 0.0},
                      {"maxAngleDeg", 0.0},
                      {"handednessMismatches", 0},
                      {"kind", "measured"},
                      {"metric", "mean angle between corner tangents, degrees"},
                      {"reference", "mikktspace (this is it)"}};
  }
  // MikkTSpace (and so every engine that bakes with it) treats a UV area at or below float's
  // FLT_MIN as none: such triangles get the fallback frame. Said in the answer, not only in stats.
  if (const auto it = out.stats.counters.find("zeroUvAreaTriangles"); it != out.stats.counters.end() && it->second > 0)
    res["warnings"] = json::array(
        {{{"pointer", "/mesh/uvs"},
          {"message",
           std::to_string(size_t(it->second)) +
               " triangles have no UV area in float (|2 x area| <= FLT_MIN, MikkTSpace's cut-off): "
               "their corners get the fallback frame. UVs scaled down to ~1e-19 land here; scale them up"}}});
  if (include.has("stats")) res["stats"] = statsJson(out.stats);
  reply.body = std::move(res);
  return reply;
}

// ---- binary glTF ---------------------------------------------------------------------------

namespace {

ApiError gltfProblem(int status, const FieldError& p) {
  std::string where = p.pointer.empty() ? "body" : p.pointer;
  return ApiError{status,
                  status == 413 ? "limit-exceeded" : "invalid-gltf",
                  status == 413 ? "Request exceeds a configured limit" : "Unusable glTF",
                  where + ": " + p.message,
                  {{p.pointer, p.message}},
                  {}};
}

void check(const std::optional<FieldError>& p, int status = 422) {
  if (p) throw gltfProblem(status, *p);
}

// An accessor index from the glTF document (`pointer` names where it was read).
int accessorIndex(const json& value, const std::string& pointer) {
  uint64_t index = 0;
  check(glb::unsignedValue(value, pointer, INT32_MAX, index));
  return int(index);
}

// The texture coordinates a primitive's tangents follow: the set its material's normal texture
// samples ("TEXCOORD_<texCoord>"), TEXCOORD_0 when it has none.
std::string normalMapUvs(const json& gltf, const json& prim, const std::string& at) {
  if (!prim.contains("material")) return "TEXCOORD_0";
  uint64_t m = 0, set = 0;
  check(glb::unsignedValue(prim["material"], at + "/material", INT32_MAX, m));
  const json& materials = gltf.contains("materials") ? gltf["materials"] : json::array();
  if (!materials.is_array() || m >= materials.size() || !materials[m].is_object())
    throw gltfProblem(422, {at + "/material", "names no material"});
  const json& material = materials[m];
  if (material.contains("normalTexture") && material["normalTexture"].is_object())
    check(glb::unsignedMember(material["normalTexture"], "texCoord",
                              "/materials/" + std::to_string(m) + "/normalTexture/texCoord", 0, 31, set));
  return "TEXCOORD_" + std::to_string(set);
}

// The mesh of one triangle primitive: its POSITION, `uvs` and NORMAL (where given,
// `hadNormals`) accessors, and its indices (or the vertices in order when it has none).
tg::Mesh readPrimitive(glb::Asset& asset, json& prim, json& attrs, const std::string& uvs, const std::string& at,
                       size_t maxVertices, bool& hadNormals) {
  tg::Mesh mesh;
  std::vector<float> pos, nrm, uv;
  check(glb::readFloats(asset, accessorIndex(attrs["POSITION"], at + "/attributes/POSITION"), 3, pos));
  check(glb::readFloats(asset, accessorIndex(attrs[uvs], at + "/attributes/" + uvs), 2, uv));
  hadNormals = attrs.contains("NORMAL");
  if (hadNormals) check(glb::readFloats(asset, accessorIndex(attrs["NORMAL"], at + "/attributes/NORMAL"), 3, nrm));
  const size_t n = pos.size() / 3;
  if (uv.size() / 2 != n || (hadNormals && nrm.size() / 3 != n))
    throw gltfProblem(422, {at + "/attributes", "attribute accessors must have the same count"});
  if (n > maxVertices)
    throw gltfProblem(413, {at + "/attributes/POSITION",
                            std::to_string(n) + " vertices exceed the limit of " + std::to_string(maxVertices)});
  mesh.positions.resize(n);
  mesh.uvs.resize(n);
  for (size_t i = 0; i < n; ++i) {
    mesh.positions[i] = {pos[3 * i], pos[3 * i + 1], pos[3 * i + 2]};
    mesh.uvs[i] = {uv[2 * i], uv[2 * i + 1]};
  }
  if (hadNormals) {
    mesh.normals.resize(n);
    for (size_t i = 0; i < n; ++i) mesh.normals[i] = {nrm[3 * i], nrm[3 * i + 1], nrm[3 * i + 2]};
  }
  if (prim.contains("indices")) {
    check(glb::readIndices(asset, accessorIndex(prim["indices"], at + "/indices"), mesh.indices));
  } else {
    mesh.indices.resize(n - n % 3);
    for (size_t i = 0; i < mesh.indices.size(); ++i) mesh.indices[i] = uint32_t(i);
  }
  return mesh;
}

// A library error on a primitive's mesh, as a problem at the accessor it came from.
[[noreturn]] void throwPrimitiveError(const effects::Error& e, const std::string& uvs, const std::string& at) {
  const FieldTable accessors = {{"positions", {at + "/attributes/POSITION", 0}},
                                {"uvs", {at + "/attributes/" + uvs, 0}},
                                {"normals", {at + "/attributes/NORMAL", 0}},
                                {"", {at + "/indices", 0}}};
  throw gltfProblem(e.kind == effects::ErrorKind::kLimitExceeded ? 413 : 422,
                    {placeField(e.field, at, accessors), e.message});
}

// The vertices were split (`remap`): every vertex attribute but those being written (and every
// morph target) gets a remapped copy of its accessor, and the primitive new indices.
void remapPrimitive(glb::Asset& asset, json& prim, json& attrs, const std::string& at, const tg::Output& out,
                    bool hadNormals) {
  for (auto& [name, index] : attrs.items()) {
    if (name == "TANGENT" || (name == "NORMAL" && !hadNormals)) continue;
    int copy = 0;
    check(glb::addRemappedAccessor(asset, accessorIndex(index, at + "/attributes/" + name), out.remap, copy));
    index = copy;
  }
  if (prim.contains("targets") && prim["targets"].is_array())
    for (size_t ti = 0; ti < prim["targets"].size(); ++ti)
      for (auto& [name, index] : prim["targets"][ti].items()) {
        int copy = 0;
        const std::string pointer = at + "/targets/" + std::to_string(ti) + "/" + name;
        check(glb::addRemappedAccessor(asset, accessorIndex(index, pointer), out.remap, copy));
        index = copy;
      }
  prim["indices"] = glb::addIndexAccessor(asset, out.indices);
}

// What became of each triangle primitive, for the X-Tangents header; and the primitives
// already done, by what determines their tangents (attributes, indices, morph targets and UV
// set): primitives sharing their accessors share the result instead of each getting a copy.
struct GlbRun {
  size_t generated = 0, kept = 0, shared = 0;
  std::map<std::string, json> done;  // key -> the primitive's attributes, indices and targets after
  double ms = 0;
};

// Adds TANGENT (and NORMAL where absent, flat as glTF prescribes) to one triangle primitive,
// from the UV set its normal texture uses. A primitive that has TANGENT keeps it unless
// `overwrite`; one without POSITION or that UV set cannot have tangents and is left alone.
void processPrimitive(glb::Asset& asset, json& prim, const std::string& at, const RequestContext& ctx, bool overwrite,
                      GlbRun& run) {
  const Config& config = ctx.config;
  json& attrs = prim["attributes"];
  if (!attrs.is_object()) return;
  const std::string uvs = normalMapUvs(asset.gltf, prim, at);
  if (!attrs.contains("POSITION") || !attrs.contains(uvs)) return;
  if (attrs.contains("TANGENT") && !overwrite) {
    ++run.kept;
    return;
  }
  const std::string key = json{attrs, prim.value("indices", json()), prim.value("targets", json()), uvs}.dump();
  if (auto it = run.done.find(key); it != run.done.end()) {
    for (const char* part : {"attributes", "indices", "targets"})
      if (it->second.contains(part)) prim[part] = it->second[part];
    ++run.shared;
    return;
  }
  bool hadNormals = false;
  const tg::Mesh mesh = readPrimitive(asset, prim, attrs, uvs, at, config.limits.maxMeshVertices, hadNormals);
  const size_t n = mesh.positions.size();
  tg::Options opt = options(ctx, tg::Mode::kMikkTSpace);
  opt.missingNormals = tg::NormalRule::kFlat;
  auto r = tg::generate(mesh, opt);
  if (!r.ok()) throwPrimitiveError(r.error(), uvs, at);
  tg::Output& out = r.value();
  flipW(out);  // glTF's UV origin is top-left
  run.ms += out.stats.elapsedMs;

  const bool identity = out.remap.size() == n;
  if (!identity) remapPrimitive(asset, prim, attrs, at, out, hadNormals);  // every attribute follows the split
  if (!hadNormals) attrs["NORMAL"] = glb::addFloatAccessor(asset, glb::floats<3>(out.normals), 3, true);
  attrs["TANGENT"] = glb::addFloatAccessor(asset, glb::floats<4>(out.tangents), 4, true);
  json& result = run.done[key];
  for (const char* part : {"attributes", "indices", "targets"})
    if (prim.contains(part)) result[part] = prim[part];
  ++run.generated;
}

// ?overwrite=true|false (default false).
bool overwriteOption(const RequestContext& ctx) {
  for (const auto& [name, value] : ctx.query)
    if (name != "overwrite") throw fieldError(400, "?" + name, "is not a parameter of a glTF body (overwrite is)");
  auto it = ctx.query.find("overwrite");
  if (it == ctx.query.end() || it->second == "false") return false;
  if (it->second == "true") return true;
  throw fieldError(400, "?overwrite", "must be true or false");
}

}  // namespace

BinaryReply handleGlb(const std::string& body, const RequestContext& ctx) {
  glb::Asset asset;
  check(glb::parse(body, asset), 400);
  const bool overwrite = overwriteOption(ctx);
  BinaryReply reply;
  reply.method = "mikktspace";
  GlbRun run;
  try {
    if (asset.gltf.contains("meshes"))
      for (size_t mi = 0; mi < asset.gltf["meshes"].size(); ++mi) {
        json& prims = asset.gltf["meshes"][mi]["primitives"];
        if (!prims.is_array()) continue;
        for (size_t pi = 0; pi < prims.size(); ++pi) {
          std::string at = "/meshes/" + std::to_string(mi) + "/primitives/" + std::to_string(pi);
          uint64_t mode = 4;
          check(glb::unsignedMember(prims[pi], "mode", at + "/mode", 4, 6, mode));
          if (mode != 4) continue;  // TRIANGLES only
          processPrimitive(asset, prims[pi], at, ctx, overwrite, run);
        }
      }
  } catch (const json::exception& e) {
    throw gltfProblem(422, {"", std::string("malformed glTF JSON: ") + e.what()});
  }
  if (run.generated + run.shared + run.kept == 0)
    throw gltfProblem(422, {"/meshes",
                            "no triangle primitive with POSITION and the texture coordinates its normal texture "
                            "uses (TEXCOORD_0 without one): nothing can have tangents"});
  glb::compact(asset);  // accessors the splits replaced, and their bytes, go
  reply.computeMs = run.ms;
  reply.headers["X-Tangents"] = "generated " + std::to_string(run.generated + run.shared) + ", kept " +
                                std::to_string(run.kept) + (overwrite ? "" : " (?overwrite=true replaces them)");
  reply.body = glb::serialize(asset);
  reply.contentType = "model/gltf-binary";
  return reply;
}

JsonReply handleTangents(const json& body, const RequestContext& ctx) {
  return runTangents(parseTangentsRequest(body, ctx), body, ctx);
}

void addTangentsEndpoints(Service& service) {
  service.addJsonEndpoint("/v1/tangents", "tangents.json", twoSteps(parseTangentsRequest, tangentsCost, runTangents));
  service.addBinaryAlternative("/v1/tangents", "model/gltf-binary", handleGlb, glbCost);
}

}  // namespace effectd
