// Seed 000's soap-bubble model on the CPU, and its icosphere mesh (see effects/bubble.h).
#include <algorithm>
#include <cmath>
#include <cstring>
#include <unordered_map>

#include <glm/geometric.hpp>

#include "effects/bubble.h"
#include "effects/tangents.h"

namespace effects::bubble {
namespace {

using glm::dvec3;
constexpr double kPi = 3.14159265358979323846;

double saturate(double x) { return std::clamp(x, 0.0, 1.0); }
double lerp(double a, double b, double s) { return a + (b - a) * s; }
dvec3 unitOr(const dvec3& v, const dvec3& fallback) {
  double l = glm::length(v);
  return l > 0 && std::isfinite(l) ? v / l : fallback;
}

}  // namespace

std::optional<Error> validate(const Params& p) {
  auto in = [](double v, double lo, double hi) { return std::isfinite(v) && v >= lo && v <= hi; };
  if (!in(p.n1, 1, 10)) return invalid("/n1", "must be in [1, 10]");
  if (!in(p.n2, 1, 10)) return invalid("/n2", "must be in [1, 10]");
  if (!in(p.deltaSpeed, 0, 1e6)) return invalid("/deltaSpeed", "must be in [0, 1e6]");
  if (!in(p.betaSpeed, 0, 1e6)) return invalid("/betaSpeed", "must be in [0, 1e6]");
  if (!in(p.muSpeed, 0, 1e6)) return invalid("/muSpeed", "must be in [0, 1e6]");
  if (!in(p.rimPower, 0, 1e3)) return invalid("/rimPower", "must be in [0, 1000]");
  if (!in(p.wobbleFrequency, 0, kMaxWobbleFrequency))
    return invalid("/wobbleFrequency", "must be in [0, " + std::to_string(int(kMaxWobbleFrequency)) + "]");
  if (!in(p.wobbleAmplitude, 0, 1e6)) return invalid("/wobbleAmplitude", "must be in [0, 1e6]");
  if (p.wobbleVariant == WobbleVariant::kRelative && p.wobbleAmplitude > 1)
    return unsatisfiable("/wobbleAmplitude", "a fraction of the radius in the relative wobble: at most 1");
  // Eqn 11's Jacobian is 1 + a k cos(...): at a k = 1 the surface creases, beyond it folds.
  if (p.wobbleAmplitude * p.wobbleFrequency > kMaxWobbleStretch)
    return unsatisfiable("/wobbleAmplitude",
                         "amplitude x frequency = " + std::to_string(p.wobbleAmplitude * p.wobbleFrequency) +
                             " exceeds " + std::to_string(kMaxWobbleStretch) +
                             ": eqn 11's Jacobian 1 + a k cos(...) would squash the surface (at 1 it folds); "
                             "lower wobbleAmplitude or wobbleFrequency");
  return std::nullopt;
}

WobbleShape wobbleDefaults(WobbleVariant v) { return v == WobbleVariant::kPaper ? kPaperWobble : kRelativeWobble; }

Film film(const Params& p, double t) {
  double a = saturate(p.muSpeed * t);  // eqn 3; t < 0 counts as 0
  if (std::isnan(a)) a = 0;
  return {lerp(1.0, 0.1, a), lerp(0.1, 1.0, a)};
}

Interface interface(const Params& p, double gammaOut) {
  Interface s;
  s.gammaOut = std::clamp(gammaOut, -1.0, 1.0);  // eqn 4
  s.nuOut = std::sqrt(std::max(0.0, 1.0 - s.gammaOut * s.gammaOut));
  s.nuIn = (p.n1 / p.n2) * s.nuOut;  // eqn 5 (Snell)
  s.totalInternalReflection = s.nuIn >= 1.0;
  s.gammaIn = s.totalInternalReflection ? 0.0 : std::sqrt(1.0 - s.nuIn * s.nuIn);
  return s;
}

dvec3 reflection(const dvec3& I, const dvec3& N) { return I + 2.0 * N * glm::dot(-I, N); }  // eqn 6

dvec3 refraction(const Params& p, const dvec3& I, const dvec3& N, double bottom) {
  Interface s = interface(p, glm::dot(N, -I));
  if (s.totalInternalReflection) return dvec3(0);
  const double eta = p.n1 / p.n2;
  return (eta * I + (eta * s.gammaOut - s.gammaIn) * N) * bottom;  // eqn 7, vector form
}

dvec3 finalVector(const Params& p, const dvec3& Iin, const dvec3& Nin, double t) {
  const dvec3 I = unitOr(Iin, {0, 0, -1}), N = unitOr(Nin, {0, 0, 1});
  const Film f = film(p, t);
  return reflection(I, N) * f.top + refraction(p, I, N, f.bottom);  // eqn 8
}

double rim(const Params& p, double gammaOut) {
  double base = std::max(0.0, 1.0 - std::clamp(gammaOut, -1.0, 1.0));
  return saturate(std::pow(base, p.rimPower));  // eqn 10; pow(0, 0) = 1 by convention
}

double reducedPhase(double omega, double t) {
  if (!std::isfinite(omega) || !std::isfinite(t)) return 0.0;
  const long double twoPi = 6.283185307179586476925286766559L;
  long double x = std::fmod(static_cast<long double>(omega) * static_cast<long double>(t), twoPi);
  if (x < 0) x += twoPi;
  double r = static_cast<double>(x);
  return r >= 2 * kPi ? 0.0 : r;
}

glm::dvec2 flowOffset(const Params& p, double t) {
  double ph = reducedPhase(p.betaSpeed, t);
  return {std::sin(ph), std::cos(ph)};  // eqn 9
}

WobbleShape wobbleInObject(const Params& p, double radius) {
  const double unit = p.wobbleVariant == WobbleVariant::kRelative ? radius : 1.0;
  return {p.wobbleAmplitude * unit, p.wobbleFrequency / unit};
}

dvec3 wobble(const Params& p, const dvec3& x, double t, double radius) {
  const double ph = reducedPhase(p.deltaSpeed, t);  // eqn 11
  const auto [a, k] = wobbleInObject(p, radius);
  return {x.x + a * std::sin(ph + k * x.x), x.y + a * std::cos(ph + k * x.y), x.z + a * std::sin(ph + k * x.z)};
}

std::optional<Error> wobbleFits(const Params& p, double radius) {
  // The paper's wobble moves every point by up to a object units: float32 positions keep ~7
  // digits, so a sphere under a thousandth of that is translated whole and its shape lost.
  if (p.wobbleVariant == WobbleVariant::kPaper && radius < 1e-3 * p.wobbleAmplitude)
    return unsatisfiable("/radius", "a sphere of radius " + std::to_string(radius) + " under a wobble of " +
                                        std::to_string(p.wobbleAmplitude) +
                                        " object units collapses in float32 positions: radius must be at least "
                                        "1e-3 x wobbleAmplitude (or the wobble off)");
  return std::nullopt;
}

dvec3 moveTowards(const dvec3& from, const dvec3& to, double s) {
  s = std::isfinite(s) ? saturate(s) : 0.0;
  return from + (to - from) * s;
}

namespace {

// The icosphere's vertices on the unit sphere, and its triangles (three indices each).
struct Sphere {
  std::vector<dvec3> v;
  std::vector<uint32_t> tri;
};

// Unit icosahedron, then `level` subdivisions with shared midpoints.
Sphere subdivide(int level) {
  const double g = (1 + std::sqrt(5.0)) / 2;
  std::vector<dvec3> v = {{-1, g, 0},  {1, g, 0},  {-1, -g, 0}, {1, -g, 0}, {0, -1, g},  {0, 1, g},
                          {0, -1, -g}, {0, 1, -g}, {g, 0, -1},  {g, 0, 1},  {-g, 0, -1}, {-g, 0, 1}};
  for (auto& x : v) x = glm::normalize(x);
  std::vector<uint32_t> tri = {0, 11, 5,  0, 5,  1, 0, 1, 7, 0, 7,  10, 0, 10, 11, 1, 5, 9, 5, 11,
                               4, 11, 10, 2, 10, 7, 6, 7, 1, 8, 3,  9,  4, 3,  4,  2, 3, 2, 6, 3,
                               6, 8,  3,  8, 9,  4, 9, 5, 2, 4, 11, 6,  2, 10, 8,  6, 7, 9, 8, 1};
  for (int l = 0; l < level; ++l) {
    std::unordered_map<uint64_t, uint32_t> mid;
    auto midpoint = [&](uint32_t a, uint32_t b) {
      uint64_t key = (uint64_t(std::min(a, b)) << 32) | std::max(a, b);
      auto [it, fresh] = mid.emplace(key, uint32_t(v.size()));
      if (fresh) v.push_back(glm::normalize(v[a] + v[b]));
      return it->second;
    };
    std::vector<uint32_t> next;
    next.reserve(tri.size() * 4);
    for (size_t t = 0; t < tri.size(); t += 3) {
      uint32_t a = tri[t], b = tri[t + 1], c = tri[t + 2];
      uint32_t ab = midpoint(a, b), bc = midpoint(b, c), ca = midpoint(c, a);
      next.insert(next.end(), {a, ab, ca, b, bc, ab, c, ca, bc, ab, bc, ca});
    }
    tri.swap(next);
  }
  return {std::move(v), std::move(tri)};
}

// Equirectangular UVs (u, w) of one triangle's corners `x`: a triangle across the u = 0/1
// seam gets u > 1 on its far side, and a pole the mean u of the other two corners.
void cornerUVs(const dvec3* const x[3], double u[3], double w[3]) {
  bool pole[3];
  for (int c = 0; c < 3; ++c) {
    pole[c] = std::abs(x[c]->y) > 1 - 1e-12;
    u[c] = std::atan2(x[c]->z, x[c]->x) / (2 * kPi) + 0.5;
    w[c] = 1.0 - std::acos(std::clamp(x[c]->y, -1.0, 1.0)) / kPi;
  }
  double lo = 1, hi = 0;
  for (int c = 0; c < 3; ++c)
    if (!pole[c]) lo = std::min(lo, u[c]), hi = std::max(hi, u[c]);
  if (hi - lo > 0.5)
    for (int c = 0; c < 3; ++c)
      if (!pole[c] && u[c] < 0.5) u[c] += 1.0;
  for (int c = 0; c < 3; ++c)
    if (pole[c]) {  // the pole takes the mean u of the other two corners
      double s = 0;
      int n = 0;
      for (int d = 0; d < 3; ++d)
        if (!pole[d]) s += u[d], ++n;
      u[c] = n ? s / n : 0.5;
    }
}

// The sphere scaled to the radius, wobbled if asked, with equirectangular UVs; triangles
// across the u = 0/1 seam and at the poles get own copies of their vertices.
tangents::Mesh project(const Sphere& s, const Params& p, const MeshOptions& o) {
  tangents::Mesh m;
  std::unordered_map<uint64_t, uint32_t> copies;
  auto vertex = [&](uint32_t base, double u, double vv) {
    float fu = float(u);
    uint32_t bits;
    std::memcpy(&bits, &fu, 4);
    auto [it, fresh] = copies.emplace((uint64_t(base) << 32) | bits, uint32_t(m.positions.size()));
    if (fresh) {
      dvec3 x = s.v[base] * o.radius;
      if (o.wobble) x = wobble(p, x, o.t, o.radius);
      m.positions.push_back(glm::vec3(x));
      m.uvs.push_back({fu, float(vv)});
    }
    return it->second;
  };
  for (size_t t = 0; t < s.tri.size(); t += 3) {
    const dvec3* const x[3] = {&s.v[s.tri[t]], &s.v[s.tri[t + 1]], &s.v[s.tri[t + 2]]};
    double u[3], w[3];
    cornerUVs(x, u, w);
    for (int c = 0; c < 3; ++c) m.indices.push_back(vertex(s.tri[t + c], u[c], w[c]));
  }
  return m;
}

// The camera-dependent shading of every vertex: the final vector (eqn 8) and the rim (eqn 10).
void shade(const Params& p, const MeshOptions& o, Mesh& out) {
  for (size_t i = 0; i < out.positions.size(); ++i) {
    dvec3 I = unitOr(dvec3(out.positions[i]) - *o.camera, {0, 0, -1}), N(out.normals[i]);
    out.finalVectors.push_back(glm::vec3(finalVector(p, I, N, o.t)));
    out.rim.push_back(float(rim(p, glm::dot(N, -I))));
  }
}

}  // namespace

std::optional<Error> validate(const Params& p, const MeshOptions& o) {
  if (auto e = validate(p)) return e;
  if (o.level < 0 || o.level > o.maxLevel)
    return overLimit("/level", "must be in [0, " + std::to_string(o.maxLevel) + "]");
  if (!(o.radius >= 1e-6) || !std::isfinite(o.radius) || o.radius > 1e6) return invalid("/radius", "must be in [1e-6, 1e6]");
  if (o.wobble)
    if (auto e = wobbleFits(p, o.radius)) return e;
  if (!std::isfinite(o.t)) return invalid("/t", "must be finite");
  return std::nullopt;
}

Result<Mesh> icosphere(const Params& p, const MeshOptions& o) {
  if (auto e = validate(p, o)) return *e;
  Stopwatch watch;
  // Unit icosahedron, then subdivision with shared midpoints.
  const Sphere sphere = subdivide(o.level);
  // Equirectangular UVs; triangles across the u = 0/1 seam and at the poles get own copies.
  const tangents::Mesh m = project(sphere, p, o);
  // Frames: normals after the wobble, angle-weighted and smooth across the seam.
  tangents::Options to;
  to.parallel = o.parallel;
  auto frames = tangents::generate(m, to);
  if (!frames.ok()) return frames.error();
  const tangents::Output& f = frames.value();
  Mesh out;
  out.positions.reserve(f.remap.size());
  for (uint32_t r : f.remap) {
    out.positions.push_back(m.positions[r]);
    out.uvs.push_back(m.uvs[r]);
  }
  out.normals = f.normals;
  out.tangents = f.tangents;
  out.indices = f.indices;
  if (o.camera) shade(p, o, out);
  out.stats.method = "icosphere";
  out.stats.elapsedMs = watch.ms();
  out.stats.counters = {{"level", double(o.level)},
                        {"vertices", double(out.positions.size())},
                        {"triangles", double(out.indices.size() / 3)}};
  return out;
}

}  // namespace effects::bubble
