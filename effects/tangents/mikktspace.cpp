// MikkTSpace corner tangents. This follows the structure of the reference mikktspace.c (Mikkelsen 2008,
// the version shipped by Blender): weld, set aside coincident-corner triangles, per-triangle
// first-order derivatives, edge adjacency, groups by the "4 rule" (a vertex, its connected
// triangles of one UV orientation), sub-groups by frame agreement (180 degree threshold, the
// default genTangSpaceDefault uses), angle-weighted averages. The arithmetic that decides a
// result is the reference's float arithmetic, operation for operation (the "F" helpers below):
// the per-triangle derivatives, the projections into a vertex's plane, the corner angles and
// their weighted sum. On a UV sphere whose pole vertices lie sin(pi) ~ 1e-16 apart, a pole
// triangle's derivative is the difference of two edges that cancels to exactly 0 in float; the
// reference then drops that triangle's term, and double kept a unit vector along the 1e-16 edge
// (32 degrees off at the poles). The bookkeeping is written with explicit stacks instead of
// recursion, and the neighbour pairing uses a counting sort that yields the same (i0, i1, face)
// order as the reference's quicksorts.
#include <algorithm>
#include <cfloat>
#include <cmath>
#include <cstring>
#include <optional>
#include <array>

#include "steps.h"
#include "weld.h"

namespace effects::tangents {
namespace {

// mikktspace.c's SVec3 helpers, in float and in its order of operations (the file is built with
// -ffp-contract=off: no fused multiply-adds the reference does not do).
using fvec3 = glm::vec3;
bool notZeroF(float x) { return std::fabs(x) > FLT_MIN; }
bool vNotZeroF(const fvec3& v) { return notZeroF(v.x) || notZeroF(v.y) || notZeroF(v.z); }
float dotF(const fvec3& a, const fvec3& b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
fvec3 scaleF(float f, const fvec3& v) { return fvec3(f * v.x, f * v.y, f * v.z); }
float lengthF(const fvec3& v) { return std::sqrt(v.x * v.x + v.y * v.y + v.z * v.z); }
fvec3 normalizeF(const fvec3& v) { return scaleF(1 / lengthF(v), v); }
// v projected into the plane of n, normalised where not zero (the reference's "project" steps).
fvec3 projectF(const fvec3& v, const fvec3& n) {
  const fvec3 r = v - scaleF(dotF(n, v), n);
  return vNotZeroF(r) ? normalizeF(r) : r;
}

// Plain data, filled in whole by initTriInfo (in parallel, so that the threads first touch the
// pages of their own range). The edge pairing and the groups walk only the links, 16 bytes a
// triangle, which stay in cache where the derivatives would not.
struct TriLinks {
  int neighbor[3];    // across edge (i, i+1); -1: none
  bool orientPreserving;
  bool groupWithAny;  // UV area or a derivative is zero: joins any group, adds nothing
  bool zeroUvArea;
  uint8_t grouped;  // bit i: corner i has its group
};
struct TriDerivatives {
  fvec3 os, ot;  // unit first-order derivatives, sign-adjusted by orientation (or zero)
};

struct Group {
  uint32_t vertex;  // welded vertex index
  uint32_t first;   // into the member buffer; the group ends where the next begins
  bool orientPreserving;
};

struct Member {  // a good triangle and which of its corners is the group's vertex
  uint32_t face : 30;
  uint32_t corner : 2;
};

class Mikk {
 public:
  Mikk(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel, CornerTangents& out)
      : mesh_(mesh), normals_(normals), parallel_(parallel), out_(out), scale_(powerOfTwoScale(mesh)) {}

  MikkStats run() {
    const size_t triCount = mesh_.indices.size() / 3;
    out_.tangent.resize(triCount * 3);
    out_.fellBack.assign(triCount * 3, 1);  // until a group gives the corner a frame
    std::vector<uint32_t> rep = weld<8>(mesh_.positions.size(), [&](size_t i, float* k) {
      const glm::vec3& p = mesh_.positions[i];
      glm::vec3 n = glm::vec3(normals_[i]);
      const glm::vec2& t = mesh_.uvs[i];
      float v[8] = {p.x, p.y, p.z, n.x, n.y, n.z, t.x, t.y};
      std::memcpy(k, v, sizeof v);
    });

    // Triangles with two coincident corners are set aside (reference: MARK_DEGENERATE).
    std::vector<uint32_t> degenerate;
    good_.reserve(triCount);
    tri_.reserve(triCount);
    for (uint32_t t = 0; t < triCount; ++t) {
      const std::array<uint32_t, 3> v = {rep[mesh_.indices[3 * t]], rep[mesh_.indices[3 * t + 1]],
                                         rep[mesh_.indices[3 * t + 2]]};
      const glm::vec3 &a = mesh_.positions[v[0]], &b = mesh_.positions[v[1]], &c = mesh_.positions[v[2]];
      if (a == b || a == c || b == c) {
        degenerate.push_back(t);
      } else {
        good_.push_back(t);
        tri_.push_back(v);
      }
    }
    links_.resize(good_.size());
    derivatives_.resize(good_.size());
    initTriInfo();
    buildNeighbors();
    buildGroups();
    generateTSpaces();
    degenerateEpilogue(degenerate, rep);
    fallbacks();
    MikkStats stats;
    stats.degenerateTriangles = degenerate.size();
    for (const TriLinks& ti : links_) stats.zeroUvArea += ti.zeroUvArea;
    stats.groups = groups_.size();
    return stats;
  }

 private:
  uint32_t corner(size_t g, uint32_t i) const { return tri_[g][i]; }
  // The reference's float squares overflow past |x| ~ 1e19 and underflow below ~1e-19, where its
  // tangents fall back to the placeholder. A mesh whose triangles reach beyond 2^60 or stay
  // within 2^-60 is scaled by a power of two towards 1 (exact in float, the same rounding but
  // near FLT_MIN): the reference's frames at any scale. Within, nothing is scaled and the
  // arithmetic is the reference's bit for bit.
  static float powerOfTwoScale(const Mesh& m) {
    float top = 0;
    for (uint32_t v : m.indices)
      if (v < m.positions.size()) {
        const glm::vec3& p = m.positions[v];
        top = std::max({top, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
      }
    if (!(top > 0) || !std::isfinite(top) || (top >= 0x1p-60f && top <= 0x1p60f)) return 1.0f;
    return std::ldexp(1.0f, std::clamp(-std::ilogb(top), -126, 126));
  }
  fvec3 pos(uint32_t v) const { return scale_ == 1.0f ? mesh_.positions[v] : scaleF(scale_, mesh_.positions[v]); }

  void initTriInfo() {
    forRange(parallel_, good_.size(), kParallelGrain, [this](size_t begin, size_t end) { initTriInfo(begin, end); });
  }
  void initTriInfo(size_t begin, size_t end) {
    for (size_t g = begin; g < end; ++g) {
      TriLinks& ti = links_[g];
      TriDerivatives& d = derivatives_[g];
      ti = {{-1, -1, -1}, false, true, false, 0};
      d = {fvec3(0), fvec3(0)};
      const fvec3 v1 = pos(corner(g, 0)), v2 = pos(corner(g, 1)), v3 = pos(corner(g, 2));
      const glm::vec2 &t1 = mesh_.uvs[corner(g, 0)], &t2 = mesh_.uvs[corner(g, 1)], &t3 = mesh_.uvs[corner(g, 2)];
      const float t21x = t2.x - t1.x, t21y = t2.y - t1.y, t31x = t3.x - t1.x, t31y = t3.y - t1.y;
      const fvec3 d1 = v2 - v1, d2 = v3 - v1;
      const float area = t21x * t31y - t21y * t31x;                 // signed UV area x 2
      const fvec3 os = scaleF(t31y, d1) - scaleF(t21y, d2);         // mikktspace.c eq 18
      const fvec3 ot = scaleF(-t31x, d1) + scaleF(t21x, d2);        // eq 19
      ti.orientPreserving = area > 0;
      if (notZeroF(area)) {
        const float absArea = std::fabs(area), lenOs = lengthF(os), lenOt = lengthF(ot);
        const float s = ti.orientPreserving ? 1.0f : -1.0f;
        if (notZeroF(lenOs)) d.os = scaleF(s / lenOs, os);
        if (notZeroF(lenOt)) d.ot = scaleF(s / lenOt, ot);
        if (notZeroF(lenOs / absArea) && notZeroF(lenOt / absArea)) ti.groupWithAny = false;
      } else {
        ti.zeroUvArea = true;
      }
    }
  }

  // Edges sorted by (min vertex, max vertex, face); each edge pairs with the first later one
  // of reverse direction whose slot is still free (reference: BuildNeighborsFast). An edge
  // only ever pairs inside its min-vertex bucket, so buckets are sorted and paired in parallel.
  void buildNeighbors() {
    const size_t m = good_.size() * 3;
    if (m == 0) return;  // every triangle degenerate: no edges (and no bucket pointers into nothing)
    const size_t vcount = mesh_.positions.size();
    std::vector<uint32_t> start(vcount + 1, 0);
    for (size_t g = 0; g < good_.size(); ++g)
      for (uint32_t i = 0; i < 3; ++i) ++start[std::min(corner(g, i), corner(g, (i + 1) % 3)) + 1];
    for (size_t v = 0; v < vcount; ++v) start[v + 1] += start[v];
    std::vector<Edge> edges(m);
    std::vector<uint32_t> fill(start.begin(), start.end() - 1);
    for (size_t g = 0; g < good_.size(); ++g)  // stable by face within each i0 bucket
      for (uint32_t i = 0; i < 3; ++i) {
        uint32_t a = corner(g, i), b = corner(g, (i + 1) % 3);
        edges[fill[std::min(a, b)]++] = {std::max(a, b), uint32_t(g), i & 3u};
      }
    forRange(parallel_, vcount, kParallelGrain, [&](size_t begin, size_t end) {
      for (size_t v = begin; v < end; ++v)
        if (start[v] != start[v + 1]) pairBucket(edges.data() + start[v], edges.data() + start[v + 1]);
    });
  }
  struct Edge {  // i0 is the bucket's vertex
    uint32_t i1;
    uint32_t face : 30;
    uint32_t num : 2;
  };
  void pairBucket(Edge* first, Edge* last) {
    for (Edge* k = first + 1; k < last; ++k)  // buckets are small: stable insertion sort by i1
      for (Edge* j = k; j > first && (j - 1)->i1 > j->i1; --j) std::swap(*(j - 1), *j);
    for (Edge* a = first; a < last; ++a) {
      if (links_[a->face].neighbor[a->num] != -1) continue;
      uint32_t fromA = corner(a->face, a->num);
      for (Edge* b = a + 1; b < last && b->i1 == a->i1; ++b)
        if (corner(b->face, b->num) != fromA && links_[b->face].neighbor[b->num] == -1) {
          links_[a->face].neighbor[a->num] = int(b->face);
          links_[b->face].neighbor[b->num] = int(a->face);
          break;
        }
    }
  }

  int cornerOf(size_t g, uint32_t vertex) const {
    for (uint32_t i = 0; i < 3; ++i)
      if (corner(g, i) == vertex) return int(i);
    return -1;
  }

  // Reference: Build4RuleGroups + AssignRecur (depth-first, left neighbour first).
  void buildGroups() {
    std::vector<uint32_t> stack;
    members_.reserve(good_.size() * 3);
    for (size_t g = 0; g < good_.size(); ++g) {
      for (uint32_t i = 0; i < 3; ++i) {
        if (links_[g].groupWithAny || (links_[g].grouped >> i & 1)) continue;
        const uint32_t vertex = corner(g, i);
        const bool orient = links_[g].orientPreserving;
        const size_t first = members_.size();
        links_[g].grouped |= uint8_t(1u << i);
        members_.push_back({uint32_t(g), i & 3u});
        stack.clear();
        pushNeighbors(g, i, stack);
        while (!stack.empty()) {
          uint32_t f = stack.back();
          stack.pop_back();
          int k = cornerOf(f, vertex);
          TriLinks& ti = links_[f];
          if (k < 0 || (ti.grouped >> k & 1)) continue;
          if (ti.groupWithAny && ti.grouped == 0)
            ti.orientPreserving = orient;  // the reference's one order dependency
          if (ti.orientPreserving != orient) continue;
          ti.grouped |= uint8_t(1u << k);
          members_.push_back({f, uint32_t(k) & 3u});
          pushNeighbors(f, uint32_t(k), stack);
        }
        groups_.push_back({vertex, uint32_t(first), orient});
      }
    }
  }
  void pushNeighbors(size_t f, uint32_t i, std::vector<uint32_t>& stack) const {
    int left = links_[f].neighbor[i], right = links_[f].neighbor[(i + 2) % 3];
    if (right >= 0) stack.push_back(uint32_t(right));  // popped after the left subtree
    if (left >= 0) stack.push_back(uint32_t(left));
  }


  // Reference: GenerateTSpaces + EvalTspace. A face's sub-group is the set of group faces
  // whose projected frames are not opposite to its own (the unit vectors' dot > -1 for both
  // derivatives). Nearly always that is the whole group for every face, which one pass over
  // the pairs shows (a projected derivative pair with dot >= 0 before normalising cannot reach
  // -1 after); then the group is evaluated once. Otherwise each face's set is built and sets
  // are compared as sorted lists.
  void generateTSpaces() {
    forRange(parallel_, groups_.size(), kGroupGrain,
             [this](size_t begin, size_t end) { generateTSpaces(begin, end); });
  }
  void generateTSpaces(size_t begin, size_t end) {
    std::vector<dvec3> os, ot;
    std::vector<Member> subset;
    std::vector<std::pair<std::vector<Member>, dvec3>> subgroups;
    for (size_t g = begin; g < end; ++g) {
      const Group& grp = groups_[g];
      const fvec3 n = fvec3(normals_[grp.vertex]);
      const Member* faces = members_.data() + grp.first;
      const size_t k = (g + 1 < groups_.size() ? groups_[g + 1].first : members_.size()) - grp.first;
      os.resize(k);
      ot.resize(k);
      for (size_t a = 0; a < k; ++a) {
        os[a] = dvec3(projectF(derivatives_[faces[a].face].os, n));
        ot[a] = dvec3(projectF(derivatives_[faces[a].face].ot, n));
      }
      auto agree = [&](size_t a, size_t b, bool otUnit) {
        if (a == b || links_[faces[a].face].groupWithAny || links_[faces[b].face].groupWithAny) return true;
        // The reference's test, in its float arithmetic: fCosS > -1 and fCosT > -1.
        return dotF(fvec3(os[a]), fvec3(os[b])) > -1.0f &&
               (otUnit ? dotF(fvec3(ot[a]), fvec3(ot[b])) > -1.0f : glm::dot(ot[a], ot[b]) >= 0.0);
      };
      bool whole = nearTogether(faces, k, os.data(), ot.data());
      if (!whole) {
        whole = true;
        for (size_t a = 0; a < k && whole; ++a)
          for (size_t b = a + 1; b < k && whole; ++b) whole = agree(a, b, false);
      }
      if (whole) {
        store(grp, faces, k, evalTSpace(faces, k, os.data(), n));
        continue;
      }
      subgroups.clear();
      std::optional<dvec3> wholeTangent;
      for (size_t a = 0; a < k; ++a) {
        subset.clear();
        for (size_t b = 0; b < k; ++b)
          if (agree(a, b, true)) subset.push_back(faces[b]);
        dvec3 tangent;
        if (subset.size() == k) {
          if (!wholeTangent) wholeTangent = evalTSpace(faces, k, os.data(), n);
          tangent = *wholeTangent;
        } else {
          std::sort(subset.begin(), subset.end(), [](const Member& x, const Member& y) { return x.face < y.face; });
          auto same = [&](const auto& sg) {
            return std::equal(sg.first.begin(), sg.first.end(), subset.begin(), subset.end(),
                              [](const Member& x, const Member& y) { return x.face == y.face; });
          };
          auto it = std::find_if(subgroups.begin(), subgroups.end(), same);
          if (it == subgroups.end()) {
            std::vector<dvec3> subsetOs(subset.size());
            for (size_t i = 0; i < subset.size(); ++i) subsetOs[i] = dvec3(projectF(derivatives_[subset[i].face].os, n));
            subgroups.emplace_back(subset, evalTSpace(subset.data(), subset.size(), subsetOs.data(), n));
            it = subgroups.end() - 1;
          }
          tangent = it->second;
        }
        store(grp, faces + a, 1, tangent);
      }
    }
  }

  // Whether the pairwise test of generateTSpaces finds every pair of the group in agreement,
  // shown in one pass where the frames lie close together: every os within 89.9 degrees of the
  // first's puts every pair less than 180 degrees apart (dot > -1), and every ot within 42
  // degrees of the first's puts every pair less than 84 degrees apart (dot >= 0), both with
  // margins far beyond rounding. The os must be no longer than 1 + 1e-9 (a "unit" vector
  // normalised from a subnormal squared length can come out several per cent longer, and two
  // such can have dot < -1), the ot no shorter than 1e-50 (so that no square underflows). False
  // means only that the pairs must be tested one by one.
  bool nearTogether(const Member* faces, size_t k, const dvec3* os, const dvec3* ot) const {
    size_t first = 0;
    while (first < k && links_[faces[first].face].groupWithAny) ++first;
    if (first == k) return true;
    const dvec3 s0 = os[first], t0 = ot[first];
    const double t0Squared = glm::dot(t0, t0);
    constexpr double kLongest = 1 + 1e-6;  // float-normalised vectors: |v|^2 - 1 up to ~1e-7
    if (t0Squared < 1e-100 || !(glm::dot(s0, s0) <= kLongest)) return false;
    for (size_t a = first + 1; a < k; ++a) {
      if (links_[faces[a].face].groupWithAny) continue;
      const double ts = glm::dot(ot[a], t0), tSquared = glm::dot(ot[a], ot[a]);
      if (!(glm::dot(os[a], s0) >= 1e-3) || !(glm::dot(os[a], os[a]) <= kLongest) || tSquared < 1e-100 || !(ts > 0) ||
          ts * ts < 0.55 * tSquared * t0Squared)
        return false;
    }
    return true;
  }

  // The corners `faces` of a group get `tangent` (unit, in the normal's plane) unless it is zero.
  void store(const Group& grp, const Member* faces, size_t count, const dvec3& tangent) {
    if (!notZero(tangent)) return;
    const glm::vec4 t(glm::vec3(tangent), grp.orientPreserving ? 1.0f : -1.0f);
    for (size_t a = 0; a < count; ++a) {
      const size_t c = 3 * size_t(good_[faces[a].face]) + faces[a].corner;
      out_.tangent[c] = t;
      out_.fellBack[c] = 0;
    }
  }

  // Angle-weighted average of the faces' tangents `os` (already projected into n's plane), in
  // the reference's float arithmetic (EvalTspace). The corners' cosines are taken a batch at a
  // time before their arc cosines, so the projections of one corner overlap the library calls
  // of another.
  // The float sum runs in ascending face order, as the reference sums its sorted members.
  dvec3 evalTSpace(const Member* faces, size_t count, const dvec3* os, const fvec3& n) const {
    constexpr size_t kBatch = 16;
    float cosine[kBatch];
    fvec3 sum(0);
    thread_local std::vector<uint32_t> order;
    order.resize(count);
    for (size_t a = 0; a < count; ++a) order[a] = uint32_t(a);
    if (!std::is_sorted(faces, faces + count, [](const Member& x, const Member& y) { return x.face < y.face; }))
      std::sort(order.begin(), order.end(), [&](uint32_t x, uint32_t y) { return faces[x].face < faces[y].face; });
    for (size_t first = 0; first < count; first += kBatch) {
      const size_t last = std::min(count, first + kBatch);
      for (size_t j = first; j < last; ++j) {
        const size_t a = order[j];
        const uint32_t f = faces[a].face, i = faces[a].corner;
        const fvec3 p1 = pos(corner(f, i)), p0 = pos(corner(f, (i + 2) % 3)), p2 = pos(corner(f, (i + 1) % 3));
        const fvec3 v1 = projectF(p0 - p1, n), v2 = projectF(p2 - p1, n);
        cosine[j - first] = std::clamp(dotF(v1, v2), -1.0f, 1.0f);
      }
      for (size_t j = first; j < last; ++j) {
        const size_t a = order[j];
        if (!links_[faces[a].face].groupWithAny) sum = sum + scaleF(float(std::acos(double(cosine[j - first]))), fvec3(os[a]));
      }
    }
    return vNotZeroF(sum) ? dvec3(normalizeF(sum)) : dvec3(0);
  }

  // Corners of coincident-corner triangles take the frame of the first healthy corner at the
  // same welded vertex (reference: DegenEpilogue).
  void degenerateEpilogue(const std::vector<uint32_t>& degenerate, const std::vector<uint32_t>& rep) {
    if (degenerate.empty()) return;
    std::vector<uint32_t> firstCorner(mesh_.positions.size(), UINT32_MAX);
    for (size_t g = good_.size(); g-- > 0;)
      for (uint32_t i = 3; i-- > 0;) firstCorner[corner(g, i)] = uint32_t(3 * size_t(good_[g]) + i);
    for (uint32_t t : degenerate)
      for (size_t i = 0; i < 3; ++i)
        if (uint32_t from = firstCorner[rep[mesh_.indices[3 * t + i]]]; from != UINT32_MAX && !out_.fellBack[from]) {
          out_.tangent[3 * t + i] = out_.tangent[from];
          out_.fellBack[3 * t + i] = 0;
        }
  }

  // Corners with no frame: the default, in the plane of the corner's own normal.
  void fallbacks() {
    forRange(parallel_, out_.tangent.size(), kParallelGrain, [this](size_t begin, size_t end) {
      for (size_t c = begin; c < end; ++c)
        if (out_.fellBack[c]) out_.tangent[c] = fallbackTangent(normals_[mesh_.indices[c]]);
    });
  }

  const Mesh& mesh_;
  const std::vector<dvec3>& normals_;
  Parallel* parallel_;
  CornerTangents& out_;
  const float scale_;  // powerOfTwoScale
  std::vector<uint32_t> good_;                // triangles that take part, in input order
  std::vector<std::array<uint32_t, 3>> tri_;  // their welded corners
  Buffer<TriLinks> links_;                    // per good triangle
  Buffer<TriDerivatives> derivatives_;        // per good triangle
  std::vector<Group> groups_;
  std::vector<Member> members_;  // group member lists, contiguous
};

}  // namespace

CornerTangents mikktspace(const Mesh& mesh, const std::vector<dvec3>& normals, Parallel* parallel, MikkStats& stats) {
  CornerTangents out;
  stats = Mikk(mesh, normals, parallel, out).run();
  return out;
}

}  // namespace effects::tangents
