// effects/bubble: seed 000's eqns 3-11 by hand, extreme cases, long times, shader variants
// (compiled with glslangValidator), thin-film physics.
#include <unistd.h>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>

#include <gtest/gtest.h>

#include <glm/geometric.hpp>

#include <effects/bubble.h>

namespace effects::bubble {
namespace {

using glm::dvec3;

void expectVec(const dvec3& a, const dvec3& b, double tol = 1e-9) {
  EXPECT_NEAR(a.x, b.x, tol);
  EXPECT_NEAR(a.y, b.y, tol);
  EXPECT_NEAR(a.z, b.z, tol);
}
bool finite(const dvec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

TEST(Bubble, FilmThicknessEqn3) {
  Params p;  // muSpeed 0.05
  EXPECT_DOUBLE_EQ(film(p, 0).top, 1.0);
  EXPECT_DOUBLE_EQ(film(p, 0).bottom, 0.1);
  EXPECT_DOUBLE_EQ(film(p, 10).top, 0.55);  // alpha = 0.5
  EXPECT_DOUBLE_EQ(film(p, 10).bottom, 0.55);
  EXPECT_DOUBLE_EQ(film(p, 1e9).top, 0.1);  // saturated
  EXPECT_DOUBLE_EQ(film(p, -5).top, 1.0);
}

TEST(Bubble, InterfaceEqns4And5ByHand) {
  Params p;
  Interface s = interface(p, 0.6);  // nu_out = 0.8, nu_in = 0.8 / 1.33
  EXPECT_NEAR(s.nuOut, 0.8, 1e-12);
  EXPECT_NEAR(s.nuIn, 0.8 / 1.33, 1e-12);
  EXPECT_NEAR(s.gammaIn, std::sqrt(1 - std::pow(0.8 / 1.33, 2)), 1e-12);
  EXPECT_FALSE(s.totalInternalReflection);
  for (double g : {-1.0, 0.0, 1.0}) {  // N.V at the extremes
    Interface e = interface(p, g);
    EXPECT_TRUE(std::isfinite(e.gammaIn) && std::isfinite(e.nuIn));
  }
}

TEST(Bubble, ReflectionRefractionFinalByHand) {
  Params p;
  const dvec3 N(0, 0, 1), I = glm::normalize(dvec3(0.6, 0, -0.8));  // gamma_out = 0.8
  expectVec(reflection(I, N), {0.6, 0, 0.8});                       // eqn 6
  const double eta = 1 / 1.33, nuIn = eta * 0.6, gIn = std::sqrt(1 - nuIn * nuIn);
  dvec3 T = refraction(p, I, N, 1.0);  // eqn 7, vector form
  expectVec(T, eta * I + (eta * 0.8 - gIn) * N);
  EXPECT_NEAR(glm::length(T), 1.0, 1e-12);         // a unit refracted ray
  EXPECT_NEAR(T.x / glm::length(T), nuIn, 1e-12);  // Snell: sin(theta_t) = eta sin(theta_i)
  // Eqn 8 at t = 0: mu_top = 1, mu_bottom = 0.1.
  expectVec(finalVector(p, I, N, 0), reflection(I, N) + 0.1 * T);
  // Rim (eqn 10).
  EXPECT_NEAR(rim(p, 0.8), std::pow(0.2, 2.8), 1e-12);
  EXPECT_EQ(rim(p, 0.0), 1.0);
  EXPECT_EQ(rim(p, 1.0), 0.0);
  EXPECT_EQ(rim(p, -1.0), 1.0);  // back-facing: saturated
}

TEST(Bubble, TotalInternalReflectionAtGrazingIsFiniteAndReflects) {
  Params p;
  p.n1 = 1.33;  // from inside the film outwards
  p.n2 = 1.0;
  const dvec3 N(0, 0, 1), I = glm::normalize(dvec3(1, 0, -0.05));  // grazing
  Interface s = interface(p, glm::dot(N, -I));
  EXPECT_TRUE(s.totalInternalReflection);
  expectVec(refraction(p, I, N, 1.0), {0, 0, 0});
  dvec3 f = finalVector(p, I, N, 0);
  ASSERT_TRUE(finite(f));
  expectVec(f, reflection(I, N) * film(p, 0).top);  // the reflection branch alone
}

TEST(Bubble, DegenerateInputsStayFinite) {
  Params p;
  Params same;
  same.n2 = 1.0;  // n1 = n2: refraction passes straight through
  const dvec3 N(0, 0, 1), I = glm::normalize(dvec3(0.3, 0.4, -0.866));
  expectVec(refraction(same, I, N, 1.0), I, 1e-9);
  for (const dvec3& n : {dvec3(0), N, -N, dvec3(1, 0, 0)})
    for (const dvec3& i : {dvec3(0), I, -I, dvec3(1, 0, 0)})
      for (double t : {0.0, 1e-300, 1e9, 1e300}) EXPECT_TRUE(finite(finalVector(p, i, n, t)));
  Params zero = p;
  zero.muSpeed = 0;  // film never drains
  EXPECT_DOUBLE_EQ(film(zero, 1e12).top, 1.0);
}

TEST(Bubble, PhasesAtHugeTimesEqualTheReducedSmallTime) {
  Params p;
  const double t = 1e9;
  // The equivalent small time: t minus whole periods, in exact integer arithmetic for omega = 2
  // (period pi): t mod pi = 1e9 - floor(1e9 / pi) * pi, with pi in long double.
  const long double pi = 3.14159265358979323846264338327950288L;
  const double small = double(static_cast<long double>(t) - std::floor(static_cast<long double>(t) / pi) * pi);
  EXPECT_NEAR(reducedPhase(p.deltaSpeed, t), reducedPhase(p.deltaSpeed, small), 1e-6);
  const dvec3 x(0.3, -0.2, 0.9);
  expectVec(wobble(p, x, t, 1.0), wobble(p, x, small, 1.0), 1e-6);
  // Naive float evaluation is far off: delta * t = 2e9 + 1 rounds to 2e9 in a float.
  const double t2 = 1e9 + 0.5;
  double naivePhase = double(float(p.deltaSpeed * t2));
  EXPECT_GT(std::abs(std::remainder(naivePhase - reducedPhase(p.deltaSpeed, t2), 2 * M_PI)), 0.5);
  for (double big : {1e12, 1e15, -1e9}) {
    double ph = reducedPhase(p.betaSpeed, big);
    EXPECT_TRUE(ph >= 0 && ph < 2 * M_PI) << big;
  }
}

TEST(Bubble, WobbleAndMotionByHand) {
  Params p;
  p.wobbleVariant = WobbleVariant::kPaper;  // eqn 11 in object units
  p.wobbleAmplitude = 0.5;
  p.wobbleFrequency = 1;
  const double t = 0.25;                         // phase 0.5
  dvec3 w = wobble(p, {0.1, 0.2, 0.3}, t, 7.0);  // the paper's wobble ignores the radius
  expectVec(w, {0.1 + 0.5 * std::sin(0.6), 0.2 + 0.5 * std::cos(0.7), 0.3 + 0.5 * std::sin(0.8)}, 1e-12);
  // The relative wobble scales with the radius: a sphere 10x larger moves 10x as far.
  Params r;
  const double k = r.wobbleFrequency, a = r.wobbleAmplitude;
  w = wobble(r, {1, 2, 3}, t, 10.0);
  expectVec(w,
            {1 + 10 * a * std::sin(0.5 + k * 0.1), 2 + 10 * a * std::cos(0.5 + k * 0.2),
             3 + 10 * a * std::sin(0.5 + k * 0.3)},
            1e-12);
  expectVec(wobble(r, {0.1, 0.2, 0.3}, t, 1.0) * 10.0, w, 1e-12);
  expectVec(moveTowards({0, 0, 0}, {2, 4, 6}, 0.5), {1, 2, 3});
  expectVec(moveTowards({0, 0, 0}, {2, 4, 6}, 7), {2, 4, 6});
  EXPECT_TRUE(finite(moveTowards({0, 0, 0}, {2, 4, 6}, NAN)));
}

TEST(Bubble, WobbleThatWouldSquashOrFoldIsRefused) {
  for (WobbleVariant v : {WobbleVariant::kRelative, WobbleVariant::kPaper}) {
    Params p;
    p.wobbleVariant = v;
    const WobbleShape d = wobbleDefaults(v);
    p.wobbleAmplitude = d.amplitude, p.wobbleFrequency = d.frequency;
    EXPECT_FALSE(validate(p)) << "defaults of each variant are within the bound";
    EXPECT_LE(d.amplitude * d.frequency, kMaxWobbleStretch);
    p.wobbleAmplitude = 1.0, p.wobbleFrequency = 1.0;  // the paper's literal constants: a k = 1 folds
    auto e = validate(p);
    ASSERT_TRUE(e);
    EXPECT_EQ(e->field, "/wobbleAmplitude");
    EXPECT_EQ(e->kind, ErrorKind::kUnsatisfiable);
    p.wobbleAmplitude = 0.01, p.wobbleFrequency = 65;
    EXPECT_EQ(validate(p)->field, "/wobbleFrequency");
  }
}

// Per triangle, the signed volume of the tetrahedron (the mesh's centroid, triangle): positive
// for an outward-facing triangle of a closed star-shaped mesh.
std::vector<double> orientations(const Mesh& m) {
  dvec3 centre(0);
  for (const auto& x : m.positions) centre += dvec3(x);
  centre /= double(m.positions.size());
  std::vector<double> out;
  for (size_t t = 0; t < m.indices.size(); t += 3) {
    const dvec3 a(m.positions[m.indices[t]]), b(m.positions[m.indices[t + 1]]), c(m.positions[m.indices[t + 2]]);
    out.push_back(glm::dot(glm::cross(b - a, c - a), (a + b + c) / 3.0 - centre));
  }
  return out;
}

TEST(Bubble, NoTriangleInvertsAtAnyTimeForEveryVariant) {
  // Over a long sweep of times (phase wraps many times), at the bound a k = 0.5 and at each
  // variant's defaults, every triangle keeps its orientation and a good share of its area.
  for (WobbleVariant v : {WobbleVariant::kRelative, WobbleVariant::kPaper})
    for (double frequency : {wobbleDefaults(v).frequency, 0.5, 6.0, 16.0})
      for (int level : {1, 3}) {
        Params p;
        p.wobbleVariant = v;
        p.wobbleFrequency = frequency;
        p.wobbleAmplitude = kMaxWobbleStretch / frequency;
        MeshOptions still;
        still.level = level;
        still.wobble = false;
        const std::vector<double> rest = orientations(icosphere(p, still).value());
        double worst = 1e9;
        for (double t = 0; t < 400; t += 3.7) {
          MeshOptions o = still;
          o.wobble = true;
          o.t = t;
          auto r = icosphere(p, o);
          ASSERT_TRUE(r.ok());
          const std::vector<double> now = orientations(r.value());
          for (size_t i = 0; i < now.size(); ++i) worst = std::min(worst, now[i] / rest[i]);
        }
        // The Jacobian's diagonal stays within [0.5, 1.5]; level 1's big triangles bend more.
        EXPECT_GT(worst, 0.05) << int(v) << " k " << frequency << " level " << level;
      }
}

TEST(Bubble, IcosphereLevelsAndFrames) {
  Params p;
  for (int level : {0, 1, 3}) {
    MeshOptions o;
    o.level = level;
    o.wobble = false;
    o.camera = dvec3(0, 0, 5);
    auto r = icosphere(p, o);
    ASSERT_TRUE(r.ok());
    const Mesh& m = r.value();
    EXPECT_EQ(m.indices.size() / 3, size_t(20) << (2 * level));
    ASSERT_EQ(m.tangents.size(), m.positions.size());
    ASSERT_EQ(m.finalVectors.size(), m.positions.size());
    for (size_t i = 0; i < m.positions.size(); ++i) {
      EXPECT_NEAR(glm::length(dvec3(m.positions[i])), 1.0, 1e-6);
      EXPECT_NEAR(glm::length(dvec3(m.tangents[i])), 1.0, 1e-5);
      EXPECT_LE(std::abs(glm::dot(dvec3(m.tangents[i]), dvec3(m.normals[i]))), 1e-5);
      EXPECT_GE(m.uvs[i].x, 0.0f);
      EXPECT_LT(m.uvs[i].x, 1.5f);  // seam triangles continue past 1 (sample with REPEAT)
    }
  }
  MeshOptions tooBig;
  tooBig.level = 8;
  EXPECT_EQ(icosphere(p, tooBig).error().kind, ErrorKind::kLimitExceeded);
}

TEST(Bubble, WobbledMeshAtHugeTimeEqualsReducedTime) {
  Params p;
  MeshOptions a, b;
  a.level = b.level = 2;
  a.t = 1e9;
  const long double pi = 3.14159265358979323846264338327950288L;
  b.t = double(1e9L - std::floor(1e9L / pi) * pi);
  auto ma = icosphere(p, a), mb = icosphere(p, b);
  ASSERT_TRUE(ma.ok() && mb.ok());
  ASSERT_EQ(ma.value().positions.size(), mb.value().positions.size());
  for (size_t i = 0; i < ma.value().positions.size(); ++i)
    EXPECT_LT(glm::length(dvec3(ma.value().positions[i]) - dvec3(mb.value().positions[i])), 1e-5);
}

// ---- shaders ----

bool compiles(const std::string& source, const char* stage, std::string& log) {
  auto dir = std::filesystem::temp_directory_path();
  std::string path = (dir / ("effectd_bubble_" + std::to_string(::getpid()) + "." + stage)).string();
  std::ofstream(path) << source;
  std::string cmd = "glslangValidator " + path + " > " + path + ".log 2>&1";
  int rc = std::system(cmd.c_str());
  std::ifstream in(path + ".log");
  log.assign(std::istreambuf_iterator<char>(in), {});
  std::filesystem::remove(path);
  std::filesystem::remove(path + ".log");
  return rc == 0;
}

TEST(BubbleShader, EveryVariantCompilesAndHoldsOnlyItsFeatures) {
  ASSERT_EQ(std::system("glslangValidator -v > /dev/null 2>&1"), 0) << "glslang-tools missing: scripts/setup.sh";
  using Marks = std::vector<std::pair<std::string, std::vector<std::string>>>;
  // Per model, each feature flag's bit and what only it may put in the source.
  const Marks paperMarks = {{"reflection", {"uFilmTop"}},
                            {"refraction", {"uFilmBottom", "uEta", "nuIn"}},
                            {"rim", {"uRimPower"}},
                            {"textureFlow", {"uFlowTexture", "uFlowPhase", "vUv", "aUv"}},
                            {"wobble", {"uWobblePhase", "uWobbleAmplitude", "uWobbleFrequency"}},
                            {"iridescence", {"uThinFilm", "uThickness"}}};
  const Marks filmMarks = {{"wobble", {"uWobblePhase", "uWobbleAmplitude", "uWobbleFrequency"}},
                           {"thickness", {"uThicknessField", "vUv", "aUv"}},
                           {"backFace", {"gl_FrontFacing"}},
                           {"highlight", {"uLight"}}};
  for (Shading model : {Shading::kPaper, Shading::kFilm}) {
    const Marks& marks = model == Shading::kPaper ? paperMarks : filmMarks;
    for (int mask = 0; mask < (1 << marks.size()); ++mask) {
      Features f;
      f.shading = model;
      bool* paperFlags[] = {&f.reflection, &f.refraction, &f.rim, &f.textureFlow, &f.wobble, &f.iridescence};
      bool* filmFlags[] = {&f.wobble, &f.thickness, &f.backFace, &f.highlight};
      for (size_t k = 0; k < marks.size(); ++k)
        *(model == Shading::kPaper ? paperFlags : filmFlags)[k] = mask & (1 << k);
      for (Glsl v : {Glsl::kEs300, Glsl::kCore330}) {
        ShaderSource s = shader(f, v);
        std::string log;
        EXPECT_TRUE(compiles(s.vertex, "vert", log)) << mask << "\n" << s.vertex << log;
        EXPECT_TRUE(compiles(s.fragment, "frag", log)) << mask << "\n" << s.fragment << log;
        for (size_t k = 0; k < marks.size(); ++k) {
          bool on = mask & (1 << k);
          for (const auto& mark : marks[k].second) {
            bool present = (s.vertex + s.fragment).find(mark) != std::string::npos;
            EXPECT_EQ(present, on) << marks[k].first << " " << mark << " mask " << mask << " model " << int(model);
          }
        }
        if (model == Shading::kPaper && !(mask & 3)) {
          EXPECT_EQ(s.fragment.find("uEnvironment"), std::string::npos);
        }
        if (model == Shading::kFilm) {  // the paper's terms never reach the film
          for (const char* paper : {"uFilmTop", "uEta", "uRimPower", "uFlowTexture", "uBaseColor"})
            EXPECT_EQ((s.vertex + s.fragment).find(paper), std::string::npos) << paper;
        }
      }
    }
  }
}

// ---- film thickness ----

TEST(Thickness, DrainsThinTopThickBottomAndThinsOverTime) {
  Params p;
  ThicknessOptions o;
  o.swirl = 0;  // drainage alone
  const double top = thicknessAt(p, o, {0, 1, 0}, 0), bottom = thicknessAt(p, o, {0, -1, 0}, 0);
  EXPECT_NEAR(top, 0.0, 1e-9);
  EXPECT_NEAR(bottom, o.bottomStartNm, 1e-9);
  EXPECT_NEAR(thicknessAt(p, o, {1, 0, 0}, 0), o.bottomStartNm * std::sqrt(0.5), 1e-9);  // Mysels: sqrt depth
  // Eqn 3's alpha drives the drain: at saturate(muSpeed t) = 1 the bottom reaches bottomEndNm.
  EXPECT_NEAR(thicknessAt(p, o, {0, -1, 0}, 1 / p.muSpeed), o.bottomEndNm, 1e-9);
  EXPECT_NEAR(thicknessAt(p, o, {0, -1, 0}, 1e9), o.bottomEndNm, 1e-9);
  double previous = 1e9;
  for (double y = -1; y <= 1; y += 0.1) {  // monotone: thinner towards the top
    const double h = thicknessAt(p, o, {std::sqrt(std::max(0.0, 1 - y * y)), y, 0}, 3);
    EXPECT_LE(h, previous + 1e-9);
    previous = h;
  }
}

TEST(Thickness, SwirlMovesFilmWithoutCreatingItDeterministically) {
  Params p;
  ThicknessOptions o;
  auto a = thicknessField(p, o, 4.0), b = thicknessField(p, o, 4.0);
  ASSERT_TRUE(a.ok() && b.ok());
  EXPECT_EQ(a.value().nm, b.value().nm);
  const ThicknessField& f = a.value();
  EXPECT_EQ(f.nm.size(), size_t(o.width) * size_t(o.height));
  // The flow only moves film: every value is one the drainage profile holds at that time.
  ThicknessOptions still = o;
  still.swirl = 0;
  const double hi = thicknessAt(p, still, {0, -1, 0}, 4.0);
  double changed = 0;
  auto calm = thicknessField(p, still, 4.0);
  ASSERT_TRUE(calm.ok());
  for (size_t i = 0; i < f.nm.size(); ++i) {
    EXPECT_TRUE(std::isfinite(f.nm[i]));
    EXPECT_GE(f.nm[i], 0.0f);
    EXPECT_LE(f.nm[i], hi * (1 + 1e-6));
    changed = std::max(changed, std::abs(double(f.nm[i]) - calm.value().nm[i]));
  }
  EXPECT_GT(changed, 100.0) << "the swirl moves bands of thickness";
  // A different seed, a different swirl; the same seed at a later time, a drifted one.
  ThicknessOptions other = o;
  other.seed = 2;
  EXPECT_NE(thicknessField(p, other, 4.0).value().nm, f.nm);
  EXPECT_NE(thicknessField(p, o, 5.0).value().nm, f.nm);
  // The texture's error against the exact field is measured and small next to the range.
  EXPECT_GT(f.maxErrorNm, 0.0);
  EXPECT_LT(f.meanErrorNm, 10.0);
}

TEST(Thickness, ExtremeTimesAndParametersStayFinite) {
  Params p;
  ThicknessOptions o;
  o.width = 32, o.height = 16;
  for (double t : {-1e15, 0.0, 1e9, 1e15}) {
    auto f = thicknessField(p, o, t);
    ASSERT_TRUE(f.ok()) << t;
    for (float v : f.value().nm) EXPECT_TRUE(std::isfinite(v) && v >= 0) << t;
  }
  o.swirl = 10, o.swirlSpeed = 1e6, o.bottomStartNm = 1e5;
  auto f = thicknessField(p, o, 1e12);
  ASSERT_TRUE(f.ok());
  for (float v : f.value().nm) EXPECT_TRUE(std::isfinite(v) && v >= 0 && v <= 1e5 * 1.000001);
  EXPECT_FALSE(thicknessField(p, o, NAN).ok());
  o.swirl = 11;
  EXPECT_EQ(thicknessField(p, o, 0).error().field, "/swirl");
}

// ---- thin film ----

TEST(ThinFilm, ZeroThicknessIsThePlainAirInterface) {
  // A film of thickness 0 is no film: air against air, reflectance 0, at every angle.
  for (double c : {1.0, 0.5, 0.01}) EXPECT_EQ(filmReflectance(1.33, 0, c, 550), 0.0);
  EXPECT_EQ(filmColor(1.33, 0, 1.0, 16), glm::dvec3(0));
  // The interference maximum is the coherent sum of two interfaces: 4 R12 / (1 + R12)^2.
  const double r = (1.33 - 1) / (1.33 + 1), R12 = r * r;
  const double quarterWave = 550 / (4 * 1.33);
  EXPECT_NEAR(filmReflectance(1.33, quarterWave, 1.0, 550), 4 * R12 / ((1 + R12) * (1 + R12)), 1e-12);
  EXPECT_NEAR(filmReflectance(1.33, 2 * quarterWave, 1.0, 550), 0.0, 1e-12);  // half wave: dark
  EXPECT_NEAR(filmReflectance(1.33, 100, 0.0, 550), 1.0, 1e-12);              // grazing: total reflection
}

// Hue class of a linear sRGB colour.
std::string hue(const glm::dvec3& c) {
  double mx = std::max({c.r, c.g, c.b}), mn = std::min({c.r, c.g, c.b});
  if (mx - mn < 0.35 * mx) return "white";  // greys and near-greys
  if (c.r >= c.g && c.g > c.b) return "yellow";
  if (c.r > c.g && c.b > c.g) return "magenta";
  if (c.b >= c.r && c.b >= c.g) return "blue";
  return "other";
}

TEST(ThinFilm, KnownColourOrderWithGrowingThickness) {
  // Newton's series in reflection: black, first-order white, yellow, magenta, blue.
  EXPECT_LT(glm::length(filmColor(1.33, 10, 1.0, 400)), 0.01);  // thinner than ~30 nm: black
  std::vector<std::string> seen;
  for (double d = 80; d <= 300; d += 5) {  // below ~80 nm the film is a dark grey
    std::string h = hue(filmColor(1.33, d, 1.0, 400));
    if (h != "other" && (seen.empty() || seen.back() != h)) seen.push_back(h);
  }
  std::vector<std::string> expected = {"white", "yellow", "magenta", "blue"};
  ASSERT_GE(seen.size(), expected.size());
  EXPECT_EQ(std::vector<std::string>(seen.begin(), seen.begin() + 4), expected) << ::testing::PrintToString(seen);
}

TEST(ThinFilm, AnalyticFormFollowsSamplingWithinItsFitError) {
  // Belcour & Barla's closed form against 1 nm sampling: the same film colours within the error
  // of its Gaussian fits (docs/error-vs-time.md, thin-film section: mean 3.6); no film, no reflection.
  EXPECT_LT(glm::length(filmColorAnalytic(1.33, 0, 1.0)), 0.01);
  EXPECT_EQ(filmColorAnalytic(1.0, 300, 0.5), glm::dvec3(0));
  double sum = 0;
  int n = 0;
  for (double d = 50; d < 1000; d += 50)
    for (double c : {1.0, 0.7, 0.4}) {
      const glm::dvec3 a = filmColorAnalytic(1.33, d, c);
      EXPECT_TRUE(std::isfinite(a.x + a.y + a.z));
      sum += deltaE(a, filmColor(1.33, d, c, 400)), ++n;
    }
  EXPECT_LT(sum / n, 6.0);
  EXPECT_GT(sum / n, 0.5) << "a fit, not the same computation";
}

TEST(ThinFilm, ErrorFallsAsWavelengthSamplesGrow) {
  double previous = 1e9;
  for (int w : {3, 8, 16, 32, 81}) {
    ThinFilmOptions o;
    o.width = o.height = 32;
    o.wavelengths = w;
    auto t = thinFilmTable(o);
    ASSERT_TRUE(t.ok());
    EXPECT_LT(t.value().meanDeltaE, previous) << w;
    previous = t.value().meanDeltaE;
    for (float v : t.value().rgb) EXPECT_TRUE(std::isfinite(v));
  }
  EXPECT_LT(previous, 0.1);
}

// The incoherent limit per polarisation, 2 R12 / (1 + R12), averaged over s and p: what a film
// whose fringes are far finer than the eye's spectral resolution reflects, at every wavelength.
double incoherent(double n, double c) {
  const double ct = std::sqrt(1 - (1 - c * c) / (n * n));
  const double rs = (c - n * ct) / (c + n * ct), rp = (n * c - ct) / (n * c + ct);
  return 0.5 * (2 * rs * rs / (1 + rs * rs) + 2 * rp * rp / (1 + rp * rp));
}

// A second method for the reference: 400 000 samples of the Airy reflectance (1 000 in each
// 1 nm band, averaged by brute force) weighed by the 1 nm colour matching, before gamut mapping.
glm::dvec3 bruteForce(double n, double d, double c) {
  const SpectrumToRgb toRgb(400);
  std::vector<double> R;
  for (double nm : toRgb.wavelengthsNm()) {
    double sum = 0;
    for (int k = 0; k < 1000; ++k) sum += filmReflectance(n, d, c, nm - 0.5 + (k + 0.5) / 1000);
    R.push_back(sum / 1000);
  }
  return toRgb(R.data());
}

TEST(ThinFilm, ReferenceConvergesAndMeetsTheIncoherentLimit) {
  for (double d : {300.0, 5000.0, 1e5})
    for (double c : {1.0, 0.5, 0.1}) {
      const glm::dvec3 a = filmColorReference(1.33, d, c), b = filmColorReference(1.33, d, c, 1.0 / 48);
      EXPECT_LT(glm::length(a - b), 1e-6) << d << " nm, cos " << c;
    }
  // At 100 um the fringes are ~0.1 nm apart: the film is grey at the incoherent limit (the old
  // reference, 400 midpoint samples, was 25 % off here).
  for (double c : {1.0, 0.5, 0.1}) {
    const double limit = incoherent(1.33, c);
    const glm::dvec3 ref = filmColorReference(1.33, 1e5, c);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(ref[k], limit, 0.01 * limit) << "cos " << c << " channel " << k;
  }
  // The brute-force integral agrees with the quadrature (in gamut: both are greys or soft colours).
  for (double d : {500.0, 1e5}) {
    const glm::dvec3 ref = filmColorReference(1.33, d, 0.8), brute = bruteForce(1.33, d, 0.8);
    EXPECT_LT(deltaE(ref, intoGamut(brute)), 0.05) << d;
  }
}

TEST(ThinFilm, TableIsRightUpToTheSchemasHundredMicrometres) {
  ThinFilmOptions o;
  o.thicknessMinNm = 99000;
  o.thicknessMaxNm = 100000;
  o.width = o.height = 16;
  auto t = thinFilmTable(o);
  ASSERT_TRUE(t.ok());
  EXPECT_LT(t.value().maxDeltaE, 1.0);  // was 0.084 off on values of 0.1 (16 midpoint samples aliased)
  for (int y = 1; y < 16; ++y) {        // every texel near the incoherent grey
    const double limit = incoherent(1.33, y / 15.0);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(t.value().rgb[size_t(y * 16 + 7) * 3 + k], limit, 0.03 * limit + 1e-3);
  }
}

TEST(ThinFilm, ColoursStayInTheSrgbGamut) {
  ThinFilmOptions o;
  o.width = o.height = 64;
  auto t = thinFilmTable(o);
  ASSERT_TRUE(t.ok());
  EXPECT_GE(*std::min_element(t.value().rgb.begin(), t.value().rgb.end()), 0.0f);  // was -0.044
  // intoGamut keeps luminance and in-gamut colours; it moves a colour towards its own grey.
  const glm::dvec3 in(0.2, 0.5, 0.1), out(0.6, 0.3, -0.05);
  EXPECT_EQ(intoGamut(in), in);
  const glm::dvec3 m = intoGamut(out);
  EXPECT_GE(std::min({m.r, m.g, m.b}), 0.0);
  EXPECT_NEAR(std::min({m.r, m.g, m.b}), 0.0, 1e-12);
  auto Y = [](const glm::dvec3& c) { return 0.2126729 * c.r + 0.7151522 * c.g + 0.0721750 * c.b; };
  EXPECT_NEAR(Y(m), Y(out), 1e-12);
  EXPECT_GT(m.r - m.g, 0.0);  // the hue's order kept
}

}  // namespace
}  // namespace effects::bubble
