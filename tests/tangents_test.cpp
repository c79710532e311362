// effects/tangents: the note's per-triangle formulas by hand, MikkTSpace structure (splits,
// handedness), degenerate and extreme input. Agreement with the reference MikkTSpace itself is
// tested against the WebAssembly build in tests/mikktspace/ (ctest tangents_mikktspace_oracle).
#include <array>
#include <cmath>
#include <limits>
#include <set>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <effects/tangents.h>

namespace effects::tangents {
namespace {

using glm::dvec2;
using glm::dvec3;

Frame frameOf(dvec3 p0, dvec3 p1, dvec3 p2, dvec2 t0, dvec2 t1, dvec2 t2, dvec3 n = {0, 0, 1}) {
  const dvec3 p[3] = {p0, p1, p2};
  const dvec2 uv[3] = {t0, t1, t2};
  return triangleFrame(p, uv, n);
}

void expectVec(const glm::vec3& a, dvec3 b, double tol = 1e-6) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}

// Every output tangent unit length, orthogonal to its normal, w = +-1, all finite.
void expectValid(const Output& out) {
  ASSERT_EQ(out.tangents.size(), out.normals.size());
  for (size_t i = 0; i < out.tangents.size(); ++i) {
    glm::dvec3 t(out.tangents[i]), n(out.normals[i]);
    ASSERT_TRUE(std::isfinite(t.x) && std::isfinite(t.y) && std::isfinite(t.z)) << i;
    EXPECT_NEAR(glm::length(t), 1.0, 1e-5) << i;
    EXPECT_NEAR(glm::length(n), 1.0, 1e-5) << i;
    EXPECT_LE(std::abs(glm::dot(t, n)), 1e-5) << i;
    EXPECT_TRUE(out.tangents[i].w == 1.0f || out.tangents[i].w == -1.0f) << i;
  }
}

TEST(TriangleFrame, AxisAlignedByHand) {
  // e0 = (2,0,0), e1 = (0,3,0); u0 = 1, v0 = 0, u1 = 0, v1 = 1: det 1, T = e0, B = e1.
  Frame f = frameOf({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0}, {1, 0}, {0, 1});
  expectVec(f.tangent, {1, 0, 0});
  expectVec(f.bitangent, {0, 1, 0});
  EXPECT_EQ(f.w, 1.0f);
  EXPECT_FALSE(f.degenerate);
}

TEST(TriangleFrame, RotatedUvsByHand) {
  // UVs turned 90 degrees: u0 = 0, v0 = 1, u1 = -1, v1 = 0, det = 1:
  // T = v1 e0 - v0 e1 = -e1 = (0,-3,0); B = u0 e1 - u1 e0 = e0; N x T = (1,0,0) . B > 0.
  Frame f = frameOf({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0}, {0, 1}, {-1, 0});
  expectVec(f.tangent, {0, -1, 0});
  expectVec(f.bitangent, {1, 0, 0});
  EXPECT_EQ(f.w, 1.0f);
}

TEST(TriangleFrame, MirroredUvsFlipHandedness) {
  // u0 = -1, v0 = 0, u1 = 0, v1 = 1, det = -1: T = -e0, B = e1; (N x T) . B < 0 -> w = -1.
  Frame f = frameOf({0, 0, 0}, {2, 0, 0}, {0, 3, 0}, {0, 0}, {-1, 0}, {0, 1});
  expectVec(f.tangent, {-1, 0, 0});
  EXPECT_EQ(f.w, -1.0f);
  expectVec(f.bitangent, {0, 1, 0});  // w * (N x T) still points along +v
}

TEST(TriangleFrame, GramSchmidtRemovesTheNormalComponent) {
  // e0 = (1,0,1) leans out of the plane of N = +z: T = normalize(T - (N.T) N) = (1,0,0).
  Frame f = frameOf({0, 0, 0}, {1, 0, 1}, {0, 1, 0}, {0, 0}, {1, 0}, {0, 1});
  expectVec(f.tangent, {1, 0, 0});
  expectVec(f.bitangent, {0, 1, 0});
  // A sheared UV map: T and B not orthogonal before Gram-Schmidt; B comes out as N x T.
  Frame g = frameOf({0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 0}, {1, 0}, {0, 1});
  expectVec(g.tangent, {1, 0, 0});
  expectVec(g.bitangent, {0, 1, 0});
}

TEST(TriangleFrame, DegenerateUvsHaveADefinedFrame) {
  for (auto uvs : {std::array<dvec2, 3>{dvec2(0.5, 0.5), dvec2(0.5, 0.5), dvec2(0.5, 0.5)},  // identical
                   std::array<dvec2, 3>{dvec2(0, 0), dvec2(1, 1), dvec2(2, 2)}}) {           // collinear
    Frame f = frameOf({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, uvs[0], uvs[1], uvs[2], {0, 0, 1});
    EXPECT_TRUE(f.degenerate);
    expectVec(f.tangent, {1, 0, 0});  // MikkTSpace's placeholder, in N's plane
    EXPECT_EQ(f.w, -1.0f);
  }
  Frame f = frameOf({0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, 0}, {0, 0}, {0, 0}, {1, 0, 0});  // N along x
  EXPECT_NEAR(glm::length(glm::dvec3(f.tangent)), 1.0, 1e-6);
  EXPECT_NEAR(glm::dot(glm::dvec3(f.tangent), dvec3(1, 0, 0)), 0.0, 1e-6);
}

Mesh quad() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.uvs = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

TEST(Mikk, QuadHasOneFrame) {
  auto r = generate(quad(), {});
  ASSERT_TRUE(r.ok());
  const Output& out = r.value();
  expectValid(out);
  ASSERT_EQ(out.tangents.size(), 4u);  // nothing to split
  for (const auto& t : out.tangents) {
    expectVec(glm::vec3(t), {1, 0, 0});
    EXPECT_EQ(t.w, 1.0f);
  }
  EXPECT_EQ(out.remap, (std::vector<uint32_t>{0, 1, 2, 3}));
  EXPECT_EQ(out.stats.method, "mikktspace");
}

TEST(Mikk, MirroredHalvesSplitTheSharedVertices) {
  // Two quads sharing the edge x = 0; the left one's UVs mirror the right one's (u = |x|).
  Mesh m;
  m.positions = {{-1, 0, 0}, {0, 0, 0}, {1, 0, 0}, {-1, 1, 0}, {0, 1, 0}, {1, 1, 0}};
  m.uvs = {{1, 0}, {0, 0}, {1, 0}, {1, 1}, {0, 1}, {1, 1}};
  m.indices = {0, 1, 4, 0, 4, 3, 1, 2, 5, 1, 5, 4};
  auto r = generate(m, {});
  ASSERT_TRUE(r.ok());
  const Output& out = r.value();
  expectValid(out);
  ASSERT_EQ(out.remap.size(), 8u);  // the two centre vertices split in two
  for (uint32_t v = 0; v < 6; ++v) EXPECT_EQ(out.remap[v], v);
  EXPECT_EQ(std::set<uint32_t>(out.remap.begin() + 6, out.remap.end()), (std::set<uint32_t>{1, 4}));
  // Corners of the left quad: T = -x, w = -1; right quad: T = +x, w = +1.
  for (size_t c = 0; c < 12; ++c) {
    const glm::vec4& t = out.tangents[out.indices[c]];
    EXPECT_EQ(out.remap[out.indices[c]], m.indices[c]);
    const float side = c < 6 ? -1.0f : 1.0f;
    expectVec(glm::vec3(t), {side, 0, 0});
    EXPECT_EQ(t.w, side);
  }
}

Mesh sphere(int rings, int segments, double radius) {
  Mesh m;
  for (int r = 0; r <= rings; ++r)
    for (int s = 0; s <= segments; ++s) {
      double th = M_PI * r / rings, ph = 2 * M_PI * s / segments;
      double st = r == 0 || r == rings ? 0.0 : std::sin(th);  // poles exactly on the axis
      dvec3 p(st * std::cos(ph), std::cos(th), st * std::sin(ph));
      m.positions.push_back(glm::vec3(p * radius));
      m.uvs.push_back({float(s) / float(segments), 1.0f - float(r) / float(rings)});
    }
  const uint32_t row = uint32_t(segments) + 1;
  for (uint32_t r = 0; r < uint32_t(rings); ++r)
    for (uint32_t s = 0; s < uint32_t(segments); ++s) {
      uint32_t a = r * row + s, b = a + row;
      m.indices.insert(m.indices.end(), {a, a + 1, b, a + 1, b + 1, b});  // pole rows hold zero-area triangles
    }
  return m;
}

TEST(Mikk, ExtremeScalesStayFiniteUnitAndOrthogonal) {
  for (double radius : {1e20, 1e-20, 1.0}) {
    for (Mode mode : {Mode::kMikkTSpace, Mode::kPerTriangle, Mode::kPerVertex}) {
      Options o;
      o.mode = mode;
      auto r = generate(sphere(12, 24, radius), o);
      ASSERT_TRUE(r.ok());
      expectValid(r.value());
    }
  }
  // Same mesh scaled by 1e20 or 1e-20: the same tangents (the method is scale-invariant).
  auto a = generate(sphere(12, 24, 1.0), {}), b = generate(sphere(12, 24, 1e20), {}),
       c = generate(sphere(12, 24, 1e-20), {});
  ASSERT_EQ(a.value().tangents.size(), b.value().tangents.size());
  ASSERT_EQ(a.value().tangents.size(), c.value().tangents.size());
  for (size_t i = 0; i < a.value().tangents.size(); ++i) {
    EXPECT_LT(angleDeg(a.value().tangents[i], b.value().tangents[i]), 1e-3) << i;
    EXPECT_LT(angleDeg(a.value().tangents[i], c.value().tangents[i]), 1e-3) << i;
  }
}

TEST(Mikk, DegenerateTrianglesHaveDefinedOutput) {
  Mesh m = quad();
  m.positions.push_back({2, 0, 0});  // 4: collinear with 1 -> zero area
  m.positions.push_back({1, 0, 0});  // 5: coincides with 1
  m.uvs.push_back({2, 0});
  m.uvs.push_back({1, 0});
  m.indices.insert(m.indices.end(), {0, 1, 4, 1, 5, 2, 2, 2, 3});
  m.positions.push_back({7, 7, 7});  // 6: used by nothing
  m.uvs.push_back({0, 0});
  for (NormalRule rule : {NormalRule::kSmooth, NormalRule::kFlat})
    for (Mode mode : {Mode::kMikkTSpace, Mode::kPerTriangle, Mode::kPerVertex}) {
      Options o;
      o.mode = mode;
      o.missingNormals = rule;
      o.triangleFrames = true;
      auto r = generate(m, o);
      ASSERT_TRUE(r.ok());
      expectValid(r.value());
      EXPECT_TRUE(r.value().triangleFrames[2].degenerate);
    }
  // The healthy quad keeps its frame despite the degenerate neighbours.
  auto r = generate(m, {});
  EXPECT_GE(r.value().stats.counters.at("degenerateTriangles"), 2.0);
  expectVec(glm::vec3(r.value().tangents[0]), {1, 0, 0});
}

TEST(Mikk, FlatNormalsForMissingNormalsSplitEveryCorner) {
  Options o;
  o.missingNormals = NormalRule::kFlat;
  auto r = generate(sphere(4, 8, 1.0), o);
  ASSERT_TRUE(r.ok());
  expectValid(r.value());
  EXPECT_EQ(r.value().remap.size(), 4u * 8 * 6);  // one vertex per corner
  for (size_t c = 0; c < r.value().indices.size(); ++c) EXPECT_EQ(r.value().indices[c], c);
}

TEST(Mikk, PerTriangleErrorAgainstMikkIsMeasured) {
  Options o;
  o.mode = Mode::kPerTriangle;
  o.measureError = true;
  auto r = generate(sphere(16, 32, 1.0), o);
  ASSERT_TRUE(r.ok());
  const Stats& st = r.value().stats;
  ASSERT_TRUE(st.error.has_value());
  EXPECT_GT(*st.error, 0.1);  // flat frames differ from smoothed ones on a sphere
  EXPECT_LT(*st.error, 20.0);
  EXPECT_EQ(st.reference, "mikktspace");
  EXPECT_GT(r.value().remap.size(), sphere(16, 32, 1.0).positions.size());  // flat frames split
}

TEST(Mikk, PerVertexAverageIsCloseToMikkOnASmoothSphereAndNeverSplits) {
  Options o;
  o.mode = Mode::kPerVertex;
  o.measureError = true;
  const Mesh m = sphere(32, 64, 1.0);
  auto r = generate(m, o);
  ASSERT_TRUE(r.ok());
  expectValid(r.value());
  EXPECT_EQ(r.value().remap.size(), m.positions.size()) << "one tangent per input vertex";
  const Stats& st = r.value().stats;
  ASSERT_TRUE(st.error.has_value());
  o.mode = Mode::kPerTriangle;
  auto flat = generate(m, o);
  EXPECT_LT(*st.error, *flat.value().stats.error) << "averaging approaches MikkTSpace's smoothed frames";
  EXPECT_EQ(st.method, "perVertex");
}

TEST(Validate, RejectsBadInputNamingTheIndex) {
  Mesh m = quad();
  m.positions[2].y = std::numeric_limits<float>::quiet_NaN();
  auto r = generate(m, {});
  ASSERT_FALSE(r.ok());
  EXPECT_EQ(r.error().field, "/positions/2");
  m = quad();
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, std::numeric_limits<float>::infinity()}, {0, 0, 1}};
  EXPECT_EQ(generate(m, {}).error().field, "/normals/2");
  m = quad();
  m.indices[4] = 9;
  EXPECT_EQ(generate(m, {}).error().field, "/indices/4");
  m = quad();
  m.indices.pop_back();
  EXPECT_EQ(generate(m, {}).error().field, "/indices");
  m = quad();
  m.uvs.pop_back();
  EXPECT_EQ(generate(m, {}).error().field, "/uvs");
  Options small;
  small.maxTriangles = 1;
  EXPECT_EQ(generate(quad(), small).error().kind, ErrorKind::kLimitExceeded);
}

// Only coincident-corner triangles: nothing takes part in MikkTSpace (no edges at all), every
// corner gets the fallback (found by fuzz_glb: bucket pointers into an empty edge list).
TEST(Mikk, EveryTriangleDegenerateFallsBack) {
  Mesh m;
  m.positions = {{0, 0, 0}, {0, 0, 0}, {1, 0, 0}};
  m.uvs = {{0, 0}, {0, 0}, {1, 0}};
  m.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  m.indices = {0, 1, 2, 2, 2, 0};
  auto r = generate(m, {});
  ASSERT_TRUE(r.ok());
  expectValid(r.value());
  EXPECT_EQ(r.value().stats.counters.at("degenerateTriangles"), 2.0);
  EXPECT_EQ(r.value().stats.counters.at("fallbackCorners"), 6.0);
}

TEST(Mikk, EmptyMeshIsFine) {
  auto r = generate(Mesh{}, {});
  ASSERT_TRUE(r.ok());
  EXPECT_TRUE(r.value().tangents.empty());
}

}  // namespace
}  // namespace effects::tangents
