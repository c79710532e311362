// Tangent frames: seed 004's per-triangle TBN and MikkTSpace (see effects/tangents.h).
//
// The MikkTSpace part follows the structure of the reference mikktspace.c (Mikkelsen 2008,
// the version shipped by Blender): weld, set aside coincident-corner triangles, per-triangle
// first-order derivatives, edge adjacency, groups by the "4 rule" (a vertex, its connected
// triangles of one UV orientation), sub-groups by frame agreement (180 degree threshold, the
// default genTangSpaceDefault uses), angle-weighted averages. It is written in double with
// explicit stacks instead of recursion, and the neighbour pairing uses a counting sort that
// yields the same (i0, i1, face) order as the reference's quicksorts.
#include "effects/tangents.h"

#include <algorithm>
#include <cmath>
#include <array>
#include <cstring>
#include <limits>
#include <optional>
#include <string>
#include <thread>
#include <unordered_map>

#include <glm/geometric.hpp>

namespace effects::tangents {
namespace {

using glm::dvec2;
using glm::dvec3;

constexpr double kFloatMin = 1.17549435e-38;  // FLT_MIN: the reference's "not zero" bound on UV area

bool notZero(const dvec3& v) { return glm::dot(v, v) > 1e-300; }
dvec3 normalizeOrZero(const dvec3& v) {
  double l = glm::length(v);
  return l > 0 && std::isfinite(l) ? v / l : dvec3(0);
}
dvec3 projectToPlane(const dvec3& v, const dvec3& n) { return v - glm::dot(n, v) * n; }

// The x axis projected into the plane of unit `n`; when n lies along x, the world axis least
// aligned with n, projected.
dvec3 inPlaneAxis(const dvec3& n) {
  dvec3 t = projectToPlane(dvec3(1, 0, 0), n);
  if (glm::length(t) > 1e-6) return glm::normalize(t);
  dvec3 a = std::abs(n.y) <= std::abs(n.z) ? dvec3(0, 1, 0) : dvec3(0, 0, 1);
  return glm::normalize(projectToPlane(a, n));
}

// Welding: rep[i] = the first index whose key equals key(i) (up to 8 floats, compared as
// floats, so -0 == +0). Open addressing over the indices themselves, no per-entry allocation.
template <int N, class KeyFn>
std::vector<uint32_t> weld(size_t count, KeyFn key) {
  std::vector<std::array<float, N>> keys(count);
  for (size_t i = 0; i < count; ++i) {
    key(i, keys[i].data());
    for (float& f : keys[i]) f = f == 0.0f ? 0.0f : f;
  }
  size_t cap = 16;
  while (cap < 2 * count) cap <<= 1;
  std::vector<uint32_t> table(cap, UINT32_MAX), rep(count);
  for (size_t i = 0; i < count; ++i) {
    uint64_t h = 1469598103934665603ull;
    for (float f : keys[i]) {
      uint32_t b;
      std::memcpy(&b, &f, 4);
      h = (h ^ b) * 1099511628211ull;
    }
    size_t slot = size_t(h ^ (h >> 31)) & (cap - 1);
    while (table[slot] != UINT32_MAX && keys[table[slot]] != keys[i]) slot = (slot + 1) & (cap - 1);
    if (table[slot] == UINT32_MAX) table[slot] = uint32_t(i);
    rep[i] = table[slot];
  }
  return rep;
}

// Runs fn(begin, end) over [0, n) on up to hardware_concurrency threads (one when n is small).
// Each index is written by exactly one thread, so the result does not depend on the split.
template <class Fn>
void parallelFor(size_t n, Fn fn) {
  size_t threads = std::clamp<size_t>(std::thread::hardware_concurrency(), 1, 8);
  if (n < 20000 || threads == 1) return fn(size_t(0), n);
  std::vector<std::thread> pool;
  size_t chunk = (n + threads - 1) / threads;
  for (size_t t = 1; t < threads; ++t)
    pool.emplace_back([&, t] { fn(std::min(n, t * chunk), std::min(n, (t + 1) * chunk)); });
  fn(0, std::min(n, chunk));
  for (auto& th : pool) th.join();
}

dvec3 trianglePoint(const Mesh& m, size_t t, int c) { return dvec3(m.positions[m.indices[3 * t + size_t(c)]]); }
// Unit face normal of triangle t, zero when its area is zero.
dvec3 faceNormal(const Mesh& m, size_t t) {
  return normalizeOrZero(glm::cross(trianglePoint(m, t, 1) - trianglePoint(m, t, 0), trianglePoint(m, t, 2) - trianglePoint(m, t, 0)));
}

// Unit normals per vertex: given ones normalised; missing ones angle-weighted over all
// corners at the same position. A vertex with no usable triangle gets +z.
std::vector<dvec3> vertexNormals(const Mesh& mesh) {
  const size_t n = mesh.positions.size();
  std::vector<dvec3> out(n, dvec3(0));
  if (!mesh.normals.empty()) {
    for (size_t i = 0; i < n; ++i) {
      dvec3 v = normalizeOrZero(dvec3(mesh.normals[i]));
      out[i] = notZero(v) ? v : dvec3(0, 0, 1);
    }
    return out;
  }
  std::vector<uint32_t> at = weld<3>(n, [&](size_t i, float* k) {
    k[0] = mesh.positions[i].x, k[1] = mesh.positions[i].y, k[2] = mesh.positions[i].z;
  });
  std::vector<dvec3> sum(n, dvec3(0));
  for (size_t t = 0; t + 2 < mesh.indices.size(); t += 3) {
    dvec3 p[3];
    for (int c = 0; c < 3; ++c) p[c] = dvec3(mesh.positions[mesh.indices[t + c]]);
    dvec3 fn = faceNormal(mesh, t / 3);
    if (!notZero(fn)) continue;
    for (int c = 0; c < 3; ++c) {
      dvec3 a = normalizeOrZero(p[(c + 1) % 3] - p[c]), b = normalizeOrZero(p[(c + 2) % 3] - p[c]);
      if (!notZero(a) || !notZero(b)) continue;
      double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
      sum[at[mesh.indices[t + c]]] += angle * fn;
    }
  }
  for (size_t i = 0; i < n; ++i) {
    dvec3 v = normalizeOrZero(sum[at[i]]);
    out[i] = notZero(v) ? v : dvec3(0, 0, 1);
  }
  return out;
}

// ---- MikkTSpace ----------------------------------------------------------------------------

struct TriInfo {
  dvec3 os{0}, ot{0};   // unit first-order derivatives, sign-adjusted by orientation
  bool orientPreserving = false;
  bool groupWithAny = true;  // UV area or a derivative is zero: joins any group, adds nothing
  bool zeroUvArea = false;
  int neighbor[3] = {-1, -1, -1};  // across edge (i, i+1)
  int group[3] = {-1, -1, -1};
};

struct Group {
  uint32_t vertex;  // welded vertex index
  bool orientPreserving;
  size_t first = 0, count = 0;  // into the face buffer
};

struct Corners {
  std::vector<dvec3> tangent;  // per corner, zero where no frame
  std::vector<uint8_t> orient;
  size_t degenerateTriangles = 0, zeroUvArea = 0, groups = 0;
};

class Mikk {
 public:
  Mikk(const Mesh& mesh, const std::vector<dvec3>& normals) : mesh_(mesh), normals_(normals) {}

  Corners run() {
    const size_t triCount = mesh_.indices.size() / 3;
    out_.tangent.assign(triCount * 3, dvec3(0));
    out_.orient.assign(triCount * 3, false);
    std::vector<uint32_t> rep = weld<8>(mesh_.positions.size(), [&](size_t i, float* k) {
      const glm::vec3& p = mesh_.positions[i];
      glm::vec3 n = glm::vec3(normals_[i]);
      const glm::vec2& t = mesh_.uvs[i];
      float v[8] = {p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y};
      std::memcpy(k, v, sizeof v);
    });
    vert_.resize(triCount * 3);
    for (size_t c = 0; c < vert_.size(); ++c) vert_[c] = rep[mesh_.indices[c]];

    // Triangles with two coincident corners are set aside (reference: MARK_DEGENERATE).
    std::vector<uint32_t> degenerate;
    for (uint32_t t = 0; t < triCount; ++t) {
      const glm::vec3 &a = mesh_.positions[vert_[3 * t]], &b = mesh_.positions[vert_[3 * t + 1]],
                      &c = mesh_.positions[vert_[3 * t + 2]];
      (a == b || a == c || b == c ? degenerate : good_).push_back(t);
    }
    out_.degenerateTriangles = degenerate.size();
    info_.resize(good_.size());
    initTriInfo();
    buildNeighbors();
    buildGroups();
    generateTSpaces();
    degenerateEpilogue(degenerate);
    return std::move(out_);
  }

 private:
  dvec3 pos(uint32_t v) const { return dvec3(mesh_.positions[v]); }
  dvec2 uv(uint32_t v) const { return dvec2(mesh_.uvs[v]); }
  uint32_t corner(size_t g, int i) const { return vert_[3 * size_t(good_[g]) + size_t(i)]; }

  void initTriInfo() {
    parallelFor(good_.size(), [this](size_t begin, size_t end) { initTriInfo(begin, end); });
    for (const TriInfo& ti : info_) out_.zeroUvArea += ti.zeroUvArea;
  }
  void initTriInfo(size_t begin, size_t end) {
    for (size_t g = begin; g < end; ++g) {
      TriInfo& ti = info_[g];
      dvec3 v1 = pos(corner(g, 0)), v2 = pos(corner(g, 1)), v3 = pos(corner(g, 2));
      dvec2 t1 = uv(corner(g, 0)), t2 = uv(corner(g, 1)), t3 = uv(corner(g, 2));
      double t21x = t2.x - t1.x, t21y = t2.y - t1.y, t31x = t3.x - t1.x, t31y = t3.y - t1.y;
      dvec3 d1 = v2 - v1, d2 = v3 - v1;
      double area = t21x * t31y - t21y * t31x;  // signed UV area x 2
      dvec3 os = t31y * d1 - t21y * d2;          // mikktspace.c eq 18
      dvec3 ot = -t31x * d1 + t21x * d2;         // eq 19
      ti.orientPreserving = area > 0;
      if (std::abs(area) > kFloatMin) {
        double lenOs = glm::length(os), lenOt = glm::length(ot), s = ti.orientPreserving ? 1.0 : -1.0;
        if (lenOs > 0) ti.os = (s / lenOs) * os;
        if (lenOt > 0) ti.ot = (s / lenOt) * ot;
        if (lenOs > 0 && lenOt > 0) ti.groupWithAny = false;
      } else {
        ti.zeroUvArea = true;
      }
    }
  }

  // Edges sorted by (min vertex, max vertex, face); each edge pairs with the first later one
  // of reverse direction whose slot is still free (reference: BuildNeighborsFast).
  void buildNeighbors() {
    struct Edge {
      uint32_t i0, i1, face;
      uint8_t num;
    };
    const size_t m = good_.size() * 3;
    size_t vcount = mesh_.positions.size();
    std::vector<uint32_t> start(vcount + 1, 0);
    for (size_t g = 0; g < good_.size(); ++g)
      for (int i = 0; i < 3; ++i) ++start[std::min(corner(g, i), corner(g, (i + 1) % 3)) + 1];
    for (size_t v = 0; v < vcount; ++v) start[v + 1] += start[v];
    std::vector<Edge> edges(m);
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t g = 0; g < good_.size(); ++g)  // stable by face within each i0 bucket
      for (int i = 0; i < 3; ++i) {
        uint32_t a = corner(g, i), b = corner(g, (i + 1) % 3);
        edges[fill[std::min(a, b)]++] = {std::min(a, b), std::max(a, b), uint32_t(g), uint8_t(i)};
      }
    for (size_t v = 0; v < vcount; ++v)  // buckets are small: stable insertion sort by i1
      for (size_t k = start[v] + 1; k < start[v + 1]; ++k)
        for (size_t j = k; j > start[v] && edges[j - 1].i1 > edges[j].i1; --j) std::swap(edges[j - 1], edges[j]);
    for (size_t i = 0; i < m; ++i) {
      const Edge& a = edges[i];
      if (info_[a.face].neighbor[a.num] != -1) continue;
      uint32_t fromA = corner(a.face, a.num);
      for (size_t j = i + 1; j < m && edges[j].i0 == a.i0 && edges[j].i1 == a.i1; ++j) {
        const Edge& b = edges[j];
        if (corner(b.face, b.num) != fromA && info_[b.face].neighbor[b.num] == -1) {
          info_[a.face].neighbor[a.num] = int(b.face);
          info_[b.face].neighbor[b.num] = int(a.face);
          break;
        }
      }
    }
  }

  int cornerOf(size_t g, uint32_t vertex) const {
    for (int i = 0; i < 3; ++i)
      if (corner(g, i) == vertex) return i;
    return -1;
  }

  // Reference: Build4RuleGroups + AssignRecur (depth-first, left neighbour first).
  void buildGroups() {
    std::vector<uint32_t> stack;
    for (size_t g = 0; g < good_.size(); ++g) {
      for (int i = 0; i < 3; ++i) {
        if (info_[g].groupWithAny || info_[g].group[i] != -1) continue;
        const int gid = int(groups_.size());
        groups_.push_back({corner(g, i), info_[g].orientPreserving, faces_.size(), 0});
        info_[g].group[i] = gid;
        faces_.push_back(uint32_t(g));
        stack.clear();
        pushNeighbors(g, i, stack);
        while (!stack.empty()) {
          uint32_t f = stack.back();
          stack.pop_back();
          Group& grp = groups_[size_t(gid)];
          int k = cornerOf(f, grp.vertex);
          TriInfo& ti = info_[f];
          if (k < 0 || ti.group[k] != -1) continue;
          if (ti.groupWithAny && ti.group[0] == -1 && ti.group[1] == -1 && ti.group[2] == -1)
            ti.orientPreserving = grp.orientPreserving;  // the reference's one order dependency
          if (ti.orientPreserving != grp.orientPreserving) continue;
          ti.group[k] = gid;
          faces_.push_back(f);
          pushNeighbors(f, k, stack);
        }
        groups_[size_t(gid)].count = faces_.size() - groups_[size_t(gid)].first;
      }
    }
    out_.groups = groups_.size();
  }
  void pushNeighbors(size_t f, int i, std::vector<uint32_t>& stack) const {
    int left = info_[f].neighbor[i], right = info_[f].neighbor[(i + 2) % 3];
    if (right >= 0) stack.push_back(uint32_t(right));  // popped after the left subtree
    if (left >= 0) stack.push_back(uint32_t(left));
  }

  dvec3 projected(const dvec3& v, const dvec3& n) const { return normalizeOrZero(projectToPlane(v, n)); }

  // Reference: GenerateTSpaces + EvalTspace. A face's sub-group is the set of group faces
  // whose projected frames are not opposite to its own; nearly always the whole group, so
  // that case is evaluated once per group and other sets are compared as sorted lists.
  void generateTSpaces() {
    parallelFor(groups_.size(), [this](size_t begin, size_t end) { generateTSpaces(begin, end); });
  }
  void generateTSpaces(size_t begin, size_t end) {
    std::vector<dvec3> os, ot;
    std::vector<uint32_t> members;
    std::vector<std::pair<std::vector<uint32_t>, dvec3>> subgroups;
    for (size_t g = begin; g < end; ++g) {
      const Group& grp = groups_[g];
      const dvec3 n = normals_[grp.vertex];
      const uint32_t* faces = faces_.data() + grp.first;
      const size_t k = grp.count;
      os.resize(k);
      ot.resize(k);
      for (size_t a = 0; a < k; ++a) os[a] = projected(info_[faces[a]].os, n), ot[a] = projected(info_[faces[a]].ot, n);
      subgroups.clear();
      std::optional<dvec3> whole;
      for (size_t a = 0; a < k; ++a) {
        const uint32_t f = faces[a];
        members.clear();
        for (size_t b = 0; b < k; ++b) {
          bool any = info_[f].groupWithAny || info_[faces[b]].groupWithAny;
          if (any || a == b || (glm::dot(os[a], os[b]) > -1.0 && glm::dot(ot[a], ot[b]) > -1.0)) members.push_back(faces[b]);
        }
        dvec3 tangent;
        if (members.size() == k) {
          if (!whole) whole = evalTSpace(faces, k, os.data(), grp.vertex, n);
          tangent = *whole;
        } else {
          std::sort(members.begin(), members.end());
          auto it = std::find_if(subgroups.begin(), subgroups.end(), [&](const auto& sg) { return sg.first == members; });
          if (it == subgroups.end()) {
            std::vector<dvec3> memberOs(members.size());
            for (size_t i = 0; i < members.size(); ++i) memberOs[i] = projected(info_[members[i]].os, n);
            subgroups.emplace_back(members, evalTSpace(members.data(), members.size(), memberOs.data(), grp.vertex, n));
            it = subgroups.end() - 1;
          }
          tangent = it->second;
        }
        size_t c = 3 * size_t(good_[f]) + size_t(cornerOf(f, grp.vertex));
        out_.tangent[c] = tangent;
        out_.orient[c] = grp.orientPreserving;
      }
    }
  }

  // Angle-weighted average of the faces' tangents `os` (already projected into n's plane).
  dvec3 evalTSpace(const uint32_t* faces, size_t count, const dvec3* os, uint32_t vertex, const dvec3& n) const {
    dvec3 sum(0);
    for (size_t a = 0; a < count; ++a) {
      const uint32_t f = faces[a];
      if (info_[f].groupWithAny) continue;
      int i = cornerOf(f, vertex);
      dvec3 p1 = pos(corner(f, i)), p0 = pos(corner(f, (i + 2) % 3)), p2 = pos(corner(f, (i + 1) % 3));
      dvec3 v1 = projected(p0 - p1, n), v2 = projected(p2 - p1, n);
      double angle = std::acos(std::clamp(glm::dot(v1, v2), -1.0, 1.0));
      sum += angle * os[a];
    }
    return normalizeOrZero(sum);
  }

  // Corners of coincident-corner triangles take the frame of the first healthy corner at the
  // same welded vertex (reference: DegenEpilogue).
  void degenerateEpilogue(const std::vector<uint32_t>& degenerate) {
    if (degenerate.empty()) return;
    std::unordered_map<uint32_t, size_t> firstCorner;
    for (size_t g = 0; g < good_.size(); ++g)
      for (int i = 0; i < 3; ++i) firstCorner.emplace(corner(g, i), 3 * size_t(good_[g]) + size_t(i));
    for (uint32_t t : degenerate)
      for (size_t i = 0; i < 3; ++i)
        if (auto it = firstCorner.find(vert_[3 * t + i]); it != firstCorner.end()) {
          out_.tangent[3 * t + i] = out_.tangent[it->second];
          out_.orient[3 * t + i] = out_.orient[it->second];
        }
  }

  const Mesh& mesh_;
  const std::vector<dvec3>& normals_;
  std::vector<uint32_t> vert_;  // welded vertex per corner
  std::vector<uint32_t> good_;  // triangles that take part, in input order
  std::vector<TriInfo> info_;   // per good triangle
  std::vector<Group> groups_;
  std::vector<uint32_t> faces_;  // group face lists, contiguous
  Corners out_;
};

// ---- output assembly ---------------------------------------------------------------------

// Where no frame exists (no UV-valid triangle at the vertex) the reference emits its default
// (1, 0, 0) with w = -1, which is not orthogonal to N; effectd emits that default projected
// into N's plane, so it stays the nearest valid tangent to what every MikkTSpace tool writes.
glm::vec4 fallbackTangent(const dvec3& n) { return {glm::vec3(inPlaneAxis(n)), -1.0f}; }

// A unit tangent in n's plane from `t` (any length), or the fallback.
glm::vec4 finishTangent(const dvec3& t, bool positive, const dvec3& n, bool& fellBack) {
  dvec3 tp = projectToPlane(normalizeOrZero(t), n);
  if (glm::length(tp) > 1e-6) return {glm::vec3(glm::normalize(tp)), positive ? 1.0f : -1.0f};
  fellBack = true;
  return fallbackTangent(n);
}

Mesh flatExpanded(const Mesh& mesh, std::vector<uint32_t>& cornerToInput) {
  Mesh out;
  const size_t corners = mesh.indices.size();
  out.positions.resize(corners);
  out.uvs.resize(corners);
  out.normals.resize(corners);
  out.indices.resize(corners);
  cornerToInput = mesh.indices;
  for (size_t t = 0; t < corners / 3; ++t) {
    dvec3 fn = faceNormal(mesh, t);
    if (!notZero(fn)) fn = dvec3(0, 0, 1);
    for (size_t c = 3 * t; c < 3 * t + 3; ++c) {
      out.positions[c] = mesh.positions[mesh.indices[c]];
      out.uvs[c] = mesh.uvs[mesh.indices[c]];
      out.normals[c] = glm::vec3(fn);
      out.indices[c] = uint32_t(c);
    }
  }
  return out;
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
  dvec3 x = normalizeOrZero(dvec3(a)), y = normalizeOrZero(dvec3(b));
  return std::atan2(glm::length(glm::cross(x, y)), glm::dot(x, y)) * 180.0 / 3.14159265358979323846;
}

Frame triangleFrame(const dvec3 p[3], const dvec2 uv[3], const dvec3& nIn) {
  Frame f;
  dvec3 n = normalizeOrZero(nIn);
  if (!notZero(n)) n = dvec3(0, 0, 1);
  dvec3 e0 = p[1] - p[0], e1 = p[2] - p[0];
  double u0 = uv[1].x - uv[0].x, u1 = uv[2].x - uv[0].x, v0 = uv[1].y - uv[0].y, v1 = uv[2].y - uv[0].y;
  double det = u0 * v1 - v0 * u1;
  double scale = (std::abs(u0) + std::abs(v0)) * (std::abs(u1) + std::abs(v1));
  // [T; B] = inverse([u0 v0; u1 v1]) [e0; e1]. Only directions matter after Gram-Schmidt, so
  // the 1/det is replaced by its sign: no overflow for tiny determinants or huge coordinates.
  double s = det < 0 ? -1.0 : 1.0;
  dvec3 tRaw = s * (v1 * e0 - v0 * e1);
  dvec3 bRaw = s * (u0 * e1 - u1 * e0);
  dvec3 t = projectToPlane(normalizeOrZero(tRaw), n);
  if (std::abs(det) > 1e-12 * scale && glm::length(t) > 1e-6) {
    t = glm::normalize(t);                                       // T = normalize(T - (N.T) N)
    f.w = glm::dot(glm::cross(n, t), bRaw) < 0 ? -1.0f : 1.0f;   // handedness
  } else {
    f.degenerate = true;  // the same default as MikkTSpace's, in N's plane
    glm::vec4 d = fallbackTangent(n);
    t = dvec3(d);
    f.w = d.w;
  }
  f.tangent = glm::vec3(t);
  f.bitangent = glm::vec3(double(f.w) * glm::cross(n, t));  // B = normalize(N x T), signed
  f.normal = glm::vec3(n);
  return f;
}

std::optional<Error> validate(const Mesh& mesh, const Options& options) {
  const size_t n = mesh.positions.size();
  if (n > options.maxVertices)
    return overLimit("/positions", std::to_string(n) + " vertices exceed the limit of " + std::to_string(options.maxVertices));
  if (mesh.indices.size() % 3 != 0) return invalid("/indices", "must hold three indices per triangle");
  if (mesh.indices.size() / 3 > options.maxTriangles)
    return overLimit("/indices", std::to_string(mesh.indices.size() / 3) + " triangles exceed the limit of " +
                                     std::to_string(options.maxTriangles));
  if (mesh.uvs.size() != n) return invalid("/uvs", "must hold one UV per vertex (" + std::to_string(n) + ")");
  if (!mesh.normals.empty() && mesh.normals.size() != n)
    return invalid("/normals", "must be absent or hold one normal per vertex (" + std::to_string(n) + ")");
  auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  for (size_t i = 0; i < n; ++i) {
    if (!finite3(mesh.positions[i])) return invalid("/positions/" + std::to_string(i), "vertex " + std::to_string(i) + " is not finite");
    if (!std::isfinite(mesh.uvs[i].x) || !std::isfinite(mesh.uvs[i].y))
      return invalid("/uvs/" + std::to_string(i), "UV " + std::to_string(i) + " is not finite");
    if (!mesh.normals.empty() && !finite3(mesh.normals[i]))
      return invalid("/normals/" + std::to_string(i), "normal " + std::to_string(i) + " is not finite");
  }
  for (size_t i = 0; i < mesh.indices.size(); ++i)
    if (mesh.indices[i] >= n)
      return invalid("/indices/" + std::to_string(i),
                     "index " + std::to_string(mesh.indices[i]) + " is out of range (" + std::to_string(n) + " vertices)");
  return std::nullopt;
}

Result<Output> generate(const Mesh& meshIn, const Options& options) {
  if (auto e = validate(meshIn, options)) return *e;
  Stopwatch watch;
  // Missing normals under the flat rule: every corner becomes its own vertex first.
  std::vector<uint32_t> cornerToInput;
  Mesh expanded;
  const bool flat = meshIn.normals.empty() && options.missingNormals == NormalRule::kFlat;
  if (flat) expanded = flatExpanded(meshIn, cornerToInput);
  const Mesh& mesh = flat ? expanded : meshIn;
  const size_t triCount = mesh.indices.size() / 3, vertCount = mesh.positions.size();
  const std::vector<dvec3> normals = vertexNormals(mesh);

  Output out;
  std::vector<glm::vec4> corner(triCount * 3);
  auto triFrame = [&](size_t t, const dvec3& n) {
    dvec3 p[3];
    dvec2 uv[3];
    for (int c = 0; c < 3; ++c) {
      p[c] = trianglePoint(mesh, t, c);
      uv[c] = dvec2(mesh.uvs[mesh.indices[3 * t + size_t(c)]]);
    }
    return triangleFrame(p, uv, n);
  };
  Corners mikk;
  if (options.mode == Mode::kMikkTSpace || options.measureError) mikk = Mikk(mesh, normals).run();
  std::vector<glm::vec4> mikkCorner;
  std::vector<uint8_t> fellBack(corner.size(), 0);
  if (options.mode == Mode::kMikkTSpace || options.measureError) {
    mikkCorner.resize(triCount * 3);
    parallelFor(corner.size(), [&](size_t begin, size_t end) {
      for (size_t c = begin; c < end; ++c) {
        bool fb = false;
        // Mikk's tangent is already unit and in the plane of this corner's normal.
        const dvec3& t = mikk.tangent[c];
        if (notZero(t)) mikkCorner[c] = {glm::vec3(t), mikk.orient[c] ? 1.0f : -1.0f};
        else mikkCorner[c] = finishTangent(t, mikk.orient[c] != 0, normals[mesh.indices[c]], fb);
        fellBack[c] = fb;
      }
    });
  }
  if (options.mode == Mode::kMikkTSpace) {
    corner = std::move(mikkCorner);
  } else if (options.mode == Mode::kPerVertex) {
    std::vector<Frame> frames(triCount);
    parallelFor(triCount, [&](size_t begin, size_t end) {
      for (size_t t = begin; t < end; ++t) {
        dvec3 fn = faceNormal(mesh, t);
        frames[t] = triFrame(t, notZero(fn) ? fn : normals[mesh.indices[3 * t]]);
        if (!notZero(fn)) frames[t].degenerate = true;
      }
    });
    std::vector<dvec3> sum(vertCount, dvec3(0));
    std::vector<double> hand(vertCount, 0.0);
    for (size_t t = 0; t < triCount; ++t) {
      if (frames[t].degenerate) continue;
      for (int c = 0; c < 3; ++c) {
        dvec3 p = trianglePoint(mesh, t, c);
        dvec3 a = normalizeOrZero(trianglePoint(mesh, t, (c + 1) % 3) - p), b = normalizeOrZero(trianglePoint(mesh, t, (c + 2) % 3) - p);
        double angle = std::atan2(glm::length(glm::cross(a, b)), glm::dot(a, b));
        uint32_t v = mesh.indices[3 * t + size_t(c)];
        sum[v] += angle * dvec3(frames[t].tangent);
        hand[v] += angle * frames[t].w;
      }
    }
    std::vector<glm::vec4> perVertex(vertCount);
    std::vector<uint8_t> vertexFellBack(vertCount, 0);
    for (size_t v = 0; v < vertCount; ++v) {
      dvec3 t = projectToPlane(sum[v], normals[v]);
      const double len = glm::length(t);
      if (len > 1e-9 * glm::length(sum[v]) && len > 0) {
        perVertex[v] = glm::vec4(glm::vec3(t / len), hand[v] < 0 ? -1.0f : 1.0f);
      } else {  // no healthy frame around the vertex, or they cancel out
        perVertex[v] = fallbackTangent(normals[v]);
        vertexFellBack[v] = 1;
      }
    }
    for (size_t c = 0; c < corner.size(); ++c) {
      corner[c] = perVertex[mesh.indices[c]];
      fellBack[c] = vertexFellBack[mesh.indices[c]];
    }
  } else {
    parallelFor(corner.size(), [&](size_t begin, size_t end) {
      for (size_t c = begin; c < end; ++c) {
        Frame f = triFrame(c / 3, normals[mesh.indices[c]]);
        corner[c] = glm::vec4(f.tangent, f.w);
        fellBack[c] = f.degenerate;
      }
    });
  }
  const size_t fallbacks = size_t(std::count(fellBack.begin(), fellBack.end(), uint8_t(1)));
  const double computeMs = watch.ms();

  // Split vertices whose corners disagree; output vertex v < n is input vertex v.
  std::vector<int64_t> nextSplit(vertCount, -1);
  std::vector<bool> assigned(vertCount, false);
  out.tangents.resize(vertCount);
  out.remap.resize(vertCount);
  out.indices.resize(corner.size());
  for (uint32_t v = 0; v < vertCount; ++v) out.remap[v] = v;
  for (size_t c = 0; c < corner.size(); ++c) {
    uint32_t v = mesh.indices[c];
    if (!assigned[v]) {
      assigned[v] = true;
      out.tangents[v] = corner[c];
      out.indices[c] = v;
      continue;
    }
    int64_t k = v, last = v;
    while (k >= 0 && std::memcmp(&out.tangents[size_t(k)], &corner[c], sizeof(glm::vec4)) != 0) {
      last = k;
      k = nextSplit[size_t(k)];
    }
    if (k < 0) {
      k = int64_t(out.tangents.size());
      out.tangents.push_back(corner[c]);
      out.remap.push_back(v);
      nextSplit.push_back(-1);
      nextSplit[size_t(last)] = k;
    }
    out.indices[c] = uint32_t(k);
  }
  for (uint32_t v = 0; v < vertCount; ++v)  // vertices no triangle uses
    if (!assigned[v]) out.tangents[v] = fallbackTangent(normals[v]);
  out.normals.resize(out.remap.size());
  for (size_t k = 0; k < out.remap.size(); ++k) out.normals[k] = glm::vec3(normals[out.remap[k]]);
  if (flat)
    for (uint32_t& r : out.remap) r = cornerToInput[r];

  if (options.triangleFrames) {
    out.triangleFrames.resize(triCount);
    for (size_t t = 0; t < triCount; ++t) {
      dvec3 fn = faceNormal(mesh, t);
      out.triangleFrames[t] = triFrame(t, notZero(fn) ? fn : normals[mesh.indices[3 * t]]);
      if (!notZero(fn)) out.triangleFrames[t].degenerate = true;
    }
  }

  Stats& st = out.stats;
  st.method = toString(options.mode);
  st.elapsedMs = computeMs;
  st.counters = {{"triangles", double(triCount)},
                 {"inputVertices", double(meshIn.positions.size())},
                 {"outputVertices", double(out.remap.size())},
                 {"fallbackCorners", double(fallbacks)}};
  if (options.mode == Mode::kMikkTSpace || options.measureError) {
    st.counters["degenerateTriangles"] = double(mikk.degenerateTriangles);
    st.counters["zeroUvAreaTriangles"] = double(mikk.zeroUvArea);
    st.counters["groups"] = double(mikk.groups);
  }
  if (meshIn.normals.empty()) st.counters["computedNormals"] = 1;
  if (options.mode != Mode::kMikkTSpace && options.measureError && !corner.empty()) {
    double sum = 0, worst = 0;
    size_t flips = 0;
    for (size_t c = 0; c < corner.size(); ++c) {
      double a = angleDeg(corner[c], mikkCorner[c]);
      sum += a;
      worst = std::max(worst, a);
      flips += corner[c].w != mikkCorner[c].w;
    }
    st.error = sum / double(corner.size());
    st.errorMetric = "mean angle between corner tangents, degrees";
    st.reference = "mikktspace";
    st.counters["maxAngleDeg"] = worst;
    st.counters["handednessMismatches"] = double(flips);
  }
  return out;
}

}  // namespace effects::tangents
