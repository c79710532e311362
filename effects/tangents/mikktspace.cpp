// MikkTSpace corner tangents. This follows the structure of the reference mikktspace.c (Mikkelsen 2008,
// the version shipped by Blender): weld, set aside coincident-corner triangles, per-triangle
// first-order derivatives, edge adjacency, groups by the "4 rule" (a vertex, its connected
// triangles of one UV orientation), sub-groups by frame agreement (180 degree threshold, the
// default genTangSpaceDefault uses), angle-weighted averages. It is written in double with
// explicit stacks instead of recursion, and the neighbour pairing uses a counting sort that
// yields the same (i0, i1, face) order as the reference's quicksorts.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <optional>
#include <unordered_map>

#include "steps.h"
#include "weld.h"

namespace effects::tangents {
namespace {

constexpr double kFloatMin = 1.17549435e-38;  // FLT_MIN: the reference's "not zero" bound on UV area

struct TriInfo {
  dvec3 os{0}, ot{0};  // unit first-order derivatives, sign-adjusted by orientation
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
  Mikk(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel)
      : mesh_(mesh), normals_(normals), parallel_(parallel) {}

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
    forRange(parallel_, good_.size(), kParallelGrain, [this](size_t begin, size_t end) { initTriInfo(begin, end); });
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
      dvec3 os = t31y * d1 - t21y * d2;         // mikktspace.c eq 18
      dvec3 ot = -t31x * d1 + t21x * d2;        // eq 19
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
    forRange(parallel_, groups_.size(), kParallelGrain,
             [this](size_t begin, size_t end) { generateTSpaces(begin, end); });
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
          if (any || a == b || (glm::dot(os[a], os[b]) > -1.0 && glm::dot(ot[a], ot[b]) > -1.0))
            members.push_back(faces[b]);
        }
        dvec3 tangent;
        if (members.size() == k) {
          if (!whole) whole = evalTSpace(faces, k, os.data(), grp.vertex, n);
          tangent = *whole;
        } else {
          std::sort(members.begin(), members.end());
          auto it =
              std::find_if(subgroups.begin(), subgroups.end(), [&](const auto& sg) { return sg.first == members; });
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
  Parallel* parallel_;
  std::vector<uint32_t> vert_;  // welded vertex per corner
  std::vector<uint32_t> good_;  // triangles that take part, in input order
  std::vector<TriInfo> info_;   // per good triangle
  std::vector<Group> groups_;
  std::vector<uint32_t> faces_;  // group face lists, contiguous
  Corners out_;
};

}  // namespace

CornerTangents mikktspace(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel, MikkStats& stats) {
  Corners mikk = Mikk(mesh, normals, parallel).run();
  stats = {mikk.degenerateTriangles, mikk.zeroUvArea, mikk.groups};
  CornerTangents out;
  out.tangent.resize(mikk.tangent.size());
  out.fellBack.assign(mikk.tangent.size(), 0);
  forRange(parallel, out.tangent.size(), kParallelGrain, [&](size_t begin, size_t end) {
    for (size_t c = begin; c < end; ++c) {
      // Mikk's tangent is already unit and in the plane of this corner's normal.
      const dvec3& t = mikk.tangent[c];
      if (notZero(t)) {
        out.tangent[c] = {glm::vec3(t), mikk.orient[c] ? 1.0f : -1.0f};
      } else {  // no frame at this corner: the default, in N's plane
        out.tangent[c] = fallbackTangent(normals[mesh.indices[c]]);
        out.fellBack[c] = 1;
      }
    }
  });
  return out;
}

}  // namespace effects::tangents
