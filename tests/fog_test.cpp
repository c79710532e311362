// effects/fog: the paper's worked example, X3D semantics, stiff and extreme inputs, tables.
#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include <gtest/gtest.h>
#include <glm/geometric.hpp>

#include <effects/fog.h>

#include "fixtures.h"

namespace effects::fog {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

Fog make(FogType t) { return fixtures::fogOf(t); }

// Table options with the evenly spaced layout these tests check entries at (HEIGHT tables are
// warped by default; the warped tests say so).
TableOptions linear() {
  TableOptions o;
  o.layout = TableOptions::Layout::kLinear;
  return o;
}

const FogType kAll[] = {FogType::kX3dLinear,  FogType::kX3dExponential, FogType::kGlLinear,         FogType::kGlExp,
                        FogType::kGlExp2,     FogType::kDistanceExp2,   FogType::kDistanceGaussian, FogType::kHeight,
                        FogType::kAtmospheric};

TEST(Fog, PaperWorkedExample) {
  // Seed 003, Fig. 3: fog [0.8 0.8 0.8], object [0.7 0.2 0.1], d_c = 0.07: object colour at
  // z = 0, "only fog colour from z = 8 on". At z = 8 the largest channel is 2/255 from the fog
  // colour (0.7 * e^-4.48 = 0.0079, i.e. 2 steps of 8-bit colour); from z = 9 on within 1/255.
  Fog f;
  f.type = FogType::kDistanceExp2;
  f.distanceCoefficient = 0.07;
  const glm::dvec3 fogC{0.8}, obj{0.7, 0.2, 0.1};
  auto colour = [&](double z) {
    double w = factor(f, z);
    return w * obj + (1 - w) * fogC;
  };
  EXPECT_EQ(colour(0), obj);
  for (double z = 8; z <= 9; z += 0.25)
    for (int c = 0; c < 3; ++c) EXPECT_LE(std::lround(std::fabs(colour(z)[c] - 0.8) * 255), 2) << z;
  for (double z = 9; z < 100; z += 0.5)
    for (int c = 0; c < 3; ++c) EXPECT_LT(std::fabs(colour(z)[c] - 0.8), 1.0 / 255) << z;
  EXPECT_GT(std::fabs(colour(6)[2] - 0.8), 10.0 / 255);  // clearly not yet pure fog at z = 6
}

TEST(Fog, PaperGaussianIsTheD05Case) {
  Fog f;
  f.type = FogType::kDistanceGaussian;
  f.distanceCoefficient = 0.5;
  for (double z : {0.0, 0.5, 1.0, 2.0, 3.0})
    EXPECT_NEAR(factor(f, z), 1 / std::sqrt(2 * M_PI) * std::exp(-0.5 * z * z), 1e-15);
}

TEST(Fog, X3dSemantics) {
  Fog lin = make(FogType::kX3dLinear), ex = make(FogType::kX3dExponential);
  EXPECT_DOUBLE_EQ(factor(lin, 0), 1.0);
  EXPECT_DOUBLE_EQ(factor(lin, 25), 0.5);
  EXPECT_DOUBLE_EQ(factor(lin, 50), 0.0);
  EXPECT_DOUBLE_EQ(factor(lin, 60), 0.0);
  EXPECT_DOUBLE_EQ(factor(ex, 25), std::exp(-1.0));
  EXPECT_DOUBLE_EQ(factor(ex, 50), 0.0);
  EXPECT_LT(factor(ex, std::nextafter(50.0, 0.0)), 1e-300);  // dV -> V: no NaN, no inf
  lin.visibilityRange = ex.visibilityRange = 0;              // 0 = no fog
  EXPECT_EQ(factor(lin, 1e30), 1.0);
  EXPECT_EQ(factor(ex, kInf), 1.0);
}

TEST(Fog, GlModes) {
  Fog l = make(FogType::kGlLinear), e = make(FogType::kGlExp), e2 = make(FogType::kGlExp2);
  EXPECT_DOUBLE_EQ(factor(l, 0), 1.0);
  EXPECT_DOUBLE_EQ(factor(l, 22.5), 0.5);
  EXPECT_DOUBLE_EQ(factor(e, 20), std::exp(-1.0));
  EXPECT_DOUBLE_EQ(factor(e2, 20), std::exp(-1.0));
  // DISTANCE_EXP2 is GL_EXP2 with density sqrt(d_c).
  Fog p = make(FogType::kDistanceExp2);
  e2.density = std::sqrt(p.distanceCoefficient);
  for (double z : {0.5, 3.0, 7.0}) EXPECT_NEAR(factor(p, z), factor(e2, z), 1e-14);
}

// Property: f in [0, 1] and non-increasing in distance, over random parameters.
TEST(Fog, BoundedAndMonotoneOverRandomParameters) {
  Rng rng(7);
  for (int trial = 0; trial < 2000; ++trial) {
    Fog f = make(kAll[trial % 8]);
    auto logUniform = [&](double lo, double hi) {
      return std::exp(std::log(lo) + rng.uniform() * (std::log(hi) - std::log(lo)));
    };
    f.visibilityRange = logUniform(1e-6, 1e6);
    f.start = logUniform(1e-6, 1e3);
    f.end = f.start + logUniform(1e-6, 1e6);
    f.density = logUniform(1e-9, 1e3);
    f.distanceCoefficient = logUniform(1e-12, 1e6);
    f.peak = 0.01 + 0.99 * rng.uniform();
    f.heightFalloff = logUniform(1e-6, 100);
    ASSERT_FALSE(validate(f)) << trial;
    double prev = 2.0;
    for (int i = 0; i <= 200; ++i) {
      double d = i == 200 ? kInf : logUniform(1e-9, 1e9) * 0 + std::pow(10.0, -9 + 18.0 * i / 199.0);
      double w = factor(f, d);
      ASSERT_TRUE(w >= 0.0 && w <= 1.0) << toString(f.type) << " d=" << d << " f=" << w;
      ASSERT_LE(w, prev + 1e-15) << toString(f.type) << " d=" << d;
      prev = w;
    }
  }
}

TEST(Fog, ExtremeParametersStayFinite) {
  for (FogType t : kAll) {
    for (double dc : {0.0, 1e-12, 1e6}) {
      for (double v : {0.0, 1e-30, 1e30}) {
        Fog f = make(t);
        f.distanceCoefficient = dc;
        f.density = dc;
        f.visibilityRange = v;
        for (double d : {0.0, 1e-30, 1.0, 1e30, kInf}) {
          double w = factor(f, d);
          EXPECT_TRUE(std::isfinite(w) && w >= 0 && w <= 1) << toString(t) << " dc=" << dc << " V=" << v << " d=" << d;
        }
      }
    }
  }
}

TEST(Fog, HeightFogClosedFormMatchesRayMarching) {
  const double a = 0.3, b = 0.5, h = 1.0;
  for (double oy : {0.0, 2.0, 5.0})
    for (double dy : {-0.7, -0.1, 0.0, 1e-9, 0.3, 0.9})
      for (double t : {0.5, 10.0, 60.0}) {
        double exact = heightOpticalDepth(a, b, h, oy, dy, t);
        double marched = heightOpticalDepthMarched(a, b, h, oy, dy, t, 200000);
        EXPECT_NEAR(exact, marched, 1e-6 * std::max(1.0, exact)) << oy << " " << dy << " " << t;
      }
}

TEST(Fog, HeightFogStiffCases) {
  // Horizontal and nearly horizontal rays: the closed form must be continuous through dirY = 0.
  double flat = heightOpticalDepth(0.1, 0.5, 0, 2, 0.0, 100);
  EXPECT_NEAR(flat, 0.1 * std::exp(-1.0) * 100, 1e-12);
  for (double dy : {1e-9, -1e-9, 1e-15}) EXPECT_NEAR(heightOpticalDepth(0.1, 0.5, 0, 2, dy, 100), flat, 1e-6 * flat);
  // b = 0: uniform density; b = 100: a razor-thin layer.
  EXPECT_DOUBLE_EQ(heightOpticalDepth(0.1, 0, 0, 2, 0.5, 10), 1.0);
  double thin = heightOpticalDepth(1, 100, 0, 0, 1, 10);
  EXPECT_NEAR(thin, 1.0 / 100, 1e-12);  // all the fog is in the first centimetre
  // Camera 1e4 above the fog: e^(-b*1e4) underflows without NaN.
  for (double b : {0.0, 1e-6, 0.1, 100.0}) {
    for (double dy : {-1.0, -1e-9, 0.0, 1e-9, 1.0}) {
      for (double t : {0.0, 1.0, 1e30, kInf}) {
        for (double oy : {-1e4, 0.0, 1e4}) {
          double tau = heightOpticalDepth(0.5, b, 0, oy, dy, t);
          EXPECT_FALSE(std::isnan(tau)) << b << " " << dy << " " << t << " " << oy;
          EXPECT_GE(tau, 0.0);
          Fog f = make(FogType::kHeight);
          f.heightFalloff = b;
          double w = factor(f, {0, oy, 0}, {std::sqrt(1 - dy * dy), dy, 0}, t);
          EXPECT_TRUE(w >= 0 && w <= 1) << b << " " << dy << " " << t << " " << oy;
        }
      }
    }
  }
  // Looking straight up to infinity from inside the fog: finite depth a/b.
  EXPECT_NEAR(heightOpticalDepth(0.5, 0.25, 0, 0, 1, kInf), 2.0, 1e-12);
  EXPECT_EQ(heightOpticalDepth(0.5, 0.25, 0, 0, 0, kInf), kInf);
  EXPECT_EQ(heightOpticalDepth(0.5, 100, 0, -1e4, 0, 1), kInf);  // deep below: overflow -> inf, not NaN
}

// Height fog tables fill their rows by a recurrence (one exp per entry); every entry must equal
// the closed form at its distance and elevation to within float rounding, stiff rows included.
TEST(Fog, HeightTableEntriesEqualTheClosedForm) {
  for (double a : {1e-6, 0.02, 3.0})
    for (double b : {0.0, 1e-4, 0.1, 2.0, 100.0})
      for (double cam : {-50.0, 0.0, 3.0, 400.0})
        for (double end : {1.0, 250.0, 1e5}) {
          Fog f = make(FogType::kHeight);
          f.density = a;
          f.heightFalloff = b;
          f.baseHeight = 1.0;
          TableOptions o = linear();
          o.size = 513;
          o.elevations = 65;
          o.cameraHeight = cam;
          o.rangeStart = end / 1000;
          o.rangeEnd = end;
          o.measureError = false;
          auto t = buildTable(f, o);
          ASSERT_TRUE(t.ok()) << t.error().message;
          double worst = 0;
          for (size_t j = 0; j < t.value().height; ++j)
            for (size_t i = 0; i < t.value().width; ++i) {
              double dy = -1.0 + 2.0 * double(j) / double(t.value().height - 1);
              double d = *o.rangeStart + (end - *o.rangeStart) * double(i) / double(t.value().width - 1);
              double want = float(std::exp(-heightOpticalDepth(a, b, 1.0, cam, dy, d)));
              worst = std::max(worst, std::fabs(double(t.value().factor[j * t.value().width + i]) - want));
            }
          EXPECT_LE(worst, 2.4e-7) << a << " " << b << " " << cam << " " << end;  // 2 float ulps at 1
        }
}

// Engine terms (fog.h): startDistance shifts distance modes, maxOpacity floors f, the cutoff
// leaves far points unfogged; completeDistance lands where f meets its floor.
TEST(Fog, EngineTermsFollowTheirDefinitions) {
  Fog f = make(FogType::kGlExp);
  f.density = 0.1;
  f.startDistance = 5;
  EXPECT_EQ(factor(f, 3.0), 1.0);
  EXPECT_NEAR(factor(f, 15.0), std::exp(-1.0), 1e-15);
  f.maxOpacity = 0.6;
  EXPECT_NEAR(factor(f, 1e3), 0.4, 1e-15);
  EXPECT_NEAR(factor(f, 10.0), std::exp(-0.5), 1e-15);  // above the floor: untouched
  f.cutoffDistance = 50;
  EXPECT_NEAR(factor(f, 49.0), 0.4, 1e-15);
  EXPECT_EQ(factor(f, 51.0), 1.0);
  EXPECT_EQ(factor(f, kInf), 1.0);
  for (FogType t : kAll) {
    Fog g = make(t);
    g.startDistance = 3;
    g.maxOpacity = 0.8;
    g.cutoffDistance = 70;
    ASSERT_FALSE(validate(g)) << toString(t);
    double prev = 1.0;
    for (double d = 0; d <= 70; d += 0.25) {
      double w = factor(g, d);
      EXPECT_TRUE(w >= 1.0 - 0.8 - 1e-15 && w <= 1.0) << toString(t) << " " << d;
      EXPECT_LE(w, prev + 1e-15) << toString(t) << " " << d;
      if (d <= 3) EXPECT_EQ(w, t == FogType::kDistanceGaussian ? g.peak : 1.0) << toString(t) << " " << d;
      prev = w;
    }
    EXPECT_EQ(factor(g, 70.5), 1.0) << toString(t);
  }
  // Where f meets its floor (or 1/255), for the modes with a continuous inverse.
  for (FogType t : {FogType::kGlExp, FogType::kGlExp2, FogType::kDistanceExp2, FogType::kDistanceGaussian,
                    FogType::kHeight, FogType::kX3dExponential, FogType::kGlLinear, FogType::kX3dLinear}) {
    for (double m : {1.0, 0.9, 0.5}) {
      Fog g = make(t);
      g.startDistance = 4;
      g.maxOpacity = m;
      if (m == 1.0 && (t == FogType::kX3dLinear || t == FogType::kX3dExponential || t == FogType::kGlLinear)) continue;
      const double d = completeDistance(g, g.baseHeight);
      ASSERT_TRUE(std::isfinite(d)) << toString(t) << " " << m;
      Fog raw = g;
      raw.maxOpacity = 1.0;
      const double level = std::min(std::max(1.0 / 255, 1.0 - m), factor(raw, g.startDistance));  // the Gaussian's peak
      EXPECT_NEAR(factor(raw, d), level, 1e-9) << toString(t) << " " << m;
      g.cutoffDistance = d / 2;
      EXPECT_EQ(completeDistance(g, g.baseHeight), d / 2);
    }
  }
  Fog invisible = make(FogType::kGlExp);
  invisible.maxOpacity = 0;
  EXPECT_EQ(factor(invisible, 1e9), 1.0);
}

// Height fog with a start distance and a second layer against ray marching of both layers
// over the ray's part [start, d] (an independent evaluation of the same integral).
TEST(Fog, HeightStartAndSecondLayerMatchRayMarching) {
  Fog f = make(FogType::kHeight);
  f.density = 0.3;
  f.heightFalloff = 0.5;
  f.baseHeight = 1.0;
  f.startDistance = 7;
  f.secondLayer = HeightLayer{0.05, 0.08, 4.0};
  for (double oy : {0.0, 2.0, 9.0})
    for (double dy : {-0.7, -0.1, 0.0, 0.3, 0.9})
      for (double d : {3.0, 10.0, 60.0}) {
        double want = 1.0;
        if (d > f.startDistance) {
          const double y = oy + dy * f.startDistance, t = d - f.startDistance;
          want = std::exp(-(heightOpticalDepthMarched(0.3, 0.5, 1.0, y, dy, t, 200000) +
                            heightOpticalDepthMarched(0.05, 0.08, 4.0, y, dy, t, 200000)));
        }
        EXPECT_NEAR(factorAtElevation(f, oy, dy, d), want, 1e-7) << oy << " " << dy << " " << d;
      }
}

TEST(Fog, EngineTermsStiffCases) {
  for (double b2 : {0.0, 1e-9, 100.0})
    for (double oy : {-1e4, 0.0, 1.0, 1e4})
      for (double dy : {-1.0, -1e-9, 0.0, 1e-9, 1.0})
        for (double d : {0.0, 1e-300, 1.0, 1e30, kInf})
          for (double start : {0.0, 0.5, 1e30})
            for (double m : {0.0, 0.37, 1.0}) {
              Fog f = make(FogType::kHeight);
              f.heightFalloff = 100.0;
              f.secondLayer = HeightLayer{2.0, b2, -3.0};
              f.startDistance = start;
              f.maxOpacity = m;
              f.cutoffDistance = 1e-300 < d && d < 1e30 ? 1e20 : kInf;
              ASSERT_FALSE(validate(f));
              const double w = factorAtElevation(f, oy, dy, d);
              EXPECT_TRUE(w >= 1.0 - m && w <= 1.0)
                  << b2 << " " << oy << " " << dy << " " << d << " " << start << " " << m;
              const double c = completeDistance(f, oy);
              EXPECT_FALSE(std::isnan(c)) << b2 << " " << oy;
            }
}

TEST(Fog, EngineTermsValidation) {
  auto field = [](Fog f) { return validate(f) ? validate(f)->field : std::string("ok"); };
  Fog f = make(FogType::kGlExp);
  f.startDistance = -1;
  EXPECT_EQ(field(f), "/startDistance");
  f = make(FogType::kGlExp);
  f.maxOpacity = 1.5;
  EXPECT_EQ(field(f), "/maxOpacity");
  f.maxOpacity = std::nan("");
  EXPECT_EQ(field(f), "/maxOpacity");
  f = make(FogType::kGlExp);
  f.cutoffDistance = 0;
  EXPECT_EQ(field(f), "/cutoffDistance");
  f = make(FogType::kGlExp);
  f.secondLayer = HeightLayer{};
  EXPECT_EQ(field(f), "/secondLayer");
  f = make(FogType::kHeight);
  f.secondLayer = HeightLayer{-1, 0.1, 0};
  EXPECT_EQ(field(f), "/secondLayer/density");
  f.secondLayer = HeightLayer{1, kInf, 0};
  EXPECT_EQ(field(f), "/secondLayer/heightFalloff");
  f.secondLayer = HeightLayer{1, 0.1, std::nan("")};
  EXPECT_EQ(field(f), "/secondLayer/baseHeight");
}

// Tables end at the cutoff by default, reach the opacity floor, and hold exact values.
TEST(Fog, EngineTermsInTables) {
  Fog f = make(FogType::kHeight);
  f.density = 0.2;
  f.startDistance = 3;
  f.maxOpacity = 0.75;
  f.cutoffDistance = 30;
  f.secondLayer = HeightLayer{0.01, 0.02, 5};
  TableOptions o = linear();
  o.size = 65;
  o.elevations = 9;
  o.cameraHeight = 1;
  auto t = buildTable(f, o);
  ASSERT_TRUE(t.ok()) << t.error().message;
  EXPECT_EQ(t.value().rangeEnd, completeDistance(f, 1));  // where the floor is reached: before the cutoff
  EXPECT_LT(t.value().rangeEnd, 30.0);
  f.cutoffDistance = 8;
  t = buildTable(f, o);
  ASSERT_TRUE(t.ok()) << t.error().message;
  EXPECT_EQ(t.value().rangeEnd, 8.0);  // the cutoff comes first
  for (size_t j = 0; j < t.value().height; ++j)
    for (size_t i = 0; i < t.value().width; ++i) {
      const double dy = -1.0 + 2.0 * double(j) / double(t.value().height - 1);
      const double d = 8.0 * double(i) / double(t.value().width - 1);
      EXPECT_NEAR(t.value().factor[j * t.value().width + i], factorAtElevation(f, 1, dy, d), 1e-7) << i << " " << j;
    }
  // The last column sits exactly on a cutoff that ends the range: fogged, not rounded past it.
  for (FogType type : {FogType::kGlExp, FogType::kHeight})
    for (size_t width : {12, 23, 40, 101}) {
      Fog c = make(type);
      c.density = 0.01;
      c.heightFalloff = 0.1;
      c.cutoffDistance = type == FogType::kGlExp ? 100.0 : 123.456;
      TableOptions w = linear();
      w.size = width;
      w.elevations = type == FogType::kHeight ? 3 : 0;
      auto ct = buildTable(c, w);
      ASSERT_TRUE(ct.ok());
      ASSERT_EQ(ct.value().rangeEnd, c.cutoffDistance);
      EXPECT_LT(ct.value().factor[width - 1], 0.99) << toString(type) << " " << width;
    }
  // The same with the range starting past 0, where start + (end - start) rounds past the end
  // (4.0476... + (28.8218... - 4.0476...) > 28.8218...): height fog's fast rows too.
  Fog h = make(FogType::kHeight);
  h.density = 0.05;
  h.heightFalloff = 0.2;
  h.cutoffDistance = 28.82184447501209;
  TableOptions r = linear();
  r.size = 16;
  r.elevations = 3;
  r.cameraHeight = 2;
  r.rangeStart = 4.047608105353673;
  r.rangeEnd = h.cutoffDistance;
  ASSERT_GT(*r.rangeStart + (*r.rangeEnd - *r.rangeStart), *r.rangeEnd);  // the rounding this guards
  auto rt = buildTable(h, r);
  ASSERT_TRUE(rt.ok());
  for (size_t j = 0; j < 3; ++j) EXPECT_LT(rt.value().factor[j * 16 + 15], 0.99) << "row " << j;
  // A glow that starts late extends the default range until it is done too.
  Fog late = make(FogType::kGlExp);
  late.density = 0.1;
  late.directional = Directional{};
  late.directional->startDistance = 100;
  EXPECT_NEAR(completeDistance(late), 100 + std::log(255.0) / 0.1, 1e-9);
  Fog g = make(FogType::kGlExp);
  g.maxOpacity = 0.5;
  o = linear();
  o.maxError = 1e-3;
  auto s = buildTable(g, o);
  ASSERT_TRUE(s.ok()) << s.error().message;
  EXPECT_LE(s.value().maxError, 1e-3);
  EXPECT_NEAR(s.value().factor.back(), 0.5, 1e-6);
  EXPECT_NEAR(s.value().rangeEnd, std::log(2.0) / g.density, 1e-9);
}

// The directional lobe: 4 pi HG averages 1 over the sphere for every g, g = 0 is flat, g near
// +-1 stays finite; Unreal's form is the plain power.
TEST(Fog, DirectionalLobe) {
  for (double g : {-0.9, -0.3, 0.0, 0.5, 0.9, 0.99}) {
    Directional d;
    d.g = g;
    double sum = 0;  // (1/4pi) * integral over the sphere = (1/2) * integral of lobe(c) dc on [-1, 1]
    const int n = 400000;
    for (int i = 0; i < n; ++i) sum += lobe(d, -1.0 + 2.0 * (i + 0.5) / n);
    EXPECT_NEAR(sum / n, 1.0, 2e-3) << g;
    if (g == 0.0) EXPECT_DOUBLE_EQ(lobe(d, 0.3), 1.0);
  }
  for (double g : {-0.999999999, 0.999999999}) {
    Directional d;
    d.g = g;
    for (double c : {-1.0, -0.5, 0.0, 0.999999, 1.0}) {
      double v = lobe(d, c);
      EXPECT_TRUE(std::isfinite(v) && v >= 0) << g << " " << c << " " << v;
    }
  }
  Directional u;
  u.exponent = 8;
  EXPECT_DOUBLE_EQ(lobe(u, 0.5), std::pow(0.5, 8));
  EXPECT_EQ(lobe(u, -0.5), 0.0);
}

// The glow's weight is 1 - f over the ray's part beyond its start, under the fog's own rules,
// and shade() adds it to the fog colour.
TEST(Fog, DirectionalInscattering) {
  Fog f = make(FogType::kHeight);
  f.density = 0.2;
  f.heightFalloff = 0.3;
  f.startDistance = 2;
  f.maxOpacity = 0.9;
  f.cutoffDistance = 80;
  EXPECT_EQ(inscatterWeight(f, 0, 0.1, 30), 0.0);  // no directional
  Directional sun;
  sun.direction = {0, 0.1, -1};
  sun.startDistance = 10;
  sun.g = 0.6;
  sun.color = {4, 2, 1};
  f.directional = sun;
  ASSERT_FALSE(validate(f));
  Fog beyond = f;
  beyond.startDistance = 10;
  for (double dy : {-0.5, 0.0, 0.2})
    for (double d : {5.0, 10.0, 30.0, 79.0, 81.0}) {
      double w = inscatterWeight(f, 1.0, dy, d);
      EXPECT_DOUBLE_EQ(w, 1.0 - factorAtElevation(beyond, 1.0, dy, d)) << dy << " " << d;
      EXPECT_TRUE(w >= 0 && w <= 0.9 + 1e-15) << dy << " " << d;
      if (d <= 10 || d > 80) EXPECT_EQ(w, 0.0) << dy << " " << d;
    }
  const glm::dvec3 eye(0, 1, 0), obj(0.2, 0.4, 0.1);
  for (glm::dvec3 p : {glm::dvec3(0, 1.5, -40), glm::dvec3(30, 0, -5), glm::dvec3(0, 1, 40)}) {
    const glm::dvec3 ray = p - eye;
    const double d = glm::length(ray), fw = factor(f, eye, ray, d);
    const glm::dvec3 want =
        fw * obj + (1 - fw) * f.color +
        inscatterWeight(f, 1.0, ray.y / d, d) * sun.color * lobe(sun, glm::dot(ray / d, glm::normalize(sun.direction)));
    const glm::dvec3 got = shade(f, obj, eye, p);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], want[c], 1e-12);
  }
  EXPECT_GT(shade(f, obj, eye, {0, 1.5, -40}).r, shade(f, obj, eye, {0, 1.5, 40}).r);  // brighter towards the sun
  // Tables carry 1 - f_dir beside f, exactly, and their error covers it.
  TableOptions o = linear();
  o.size = 33;
  o.elevations = 5;
  o.cameraHeight = 1;
  auto t = buildTable(f, o);
  ASSERT_TRUE(t.ok());
  ASSERT_EQ(t.value().inscatter.size(), t.value().factor.size());
  for (size_t j = 0; j < 5; ++j)
    for (size_t i = 0; i < 33; ++i) {
      const double dy = -1.0 + 0.5 * double(j),
                   d = t.value().rangeStart + (t.value().rangeEnd - t.value().rangeStart) * double(i) / 32;
      EXPECT_NEAR(t.value().inscatter[j * 33 + i], inscatterWeight(f, 1, dy, d), 1e-7);
    }
  // Stiff: the sun on the horizon and straight overhead, g at the edges of (-1, 1), rays
  // grazing the ground, looking at the sun and away, distances from 0 to infinity.
  for (glm::dvec3 dir : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, -1)})
    for (double g : {-0.9999999, 0.0, 0.9999999})
      for (glm::dvec3 p :
           {glm::dvec3(1e6, 1, 0), glm::dvec3(-1e6, 1, 0), glm::dvec3(0, 1, -1e-9), glm::dvec3(0, 1e9, 0)}) {
        Fog h = f;
        h.directional->direction = dir;
        h.directional->g = g;
        const glm::dvec3 c = shade(h, obj, eye, p);
        for (int k = 0; k < 3; ++k) EXPECT_TRUE(std::isfinite(c[k]) && c[k] >= 0) << g << " " << p.x << " " << p.y;
      }
  // Validation names the field.
  auto field = [](Fog g) { return validate(g) ? validate(g)->field : std::string("ok"); };
  Fog bad = f;
  bad.directional->g = 1.0;
  EXPECT_EQ(field(bad), "/directional/g");
  bad = f;
  bad.directional->direction = {0, 0, 0};
  EXPECT_EQ(field(bad), "/directional/direction");
  bad = f;
  bad.directional->color = {1, -1, 0};
  EXPECT_EQ(field(bad), "/directional/color/1");
  bad = f;
  bad.directional->exponent = 0;
  EXPECT_EQ(field(bad), "/directional/exponent");
}

// Bevy's atmospheric falloff: per channel, object * e^(-extinction d) + colour * (1 - e^(-inscattering d)),
// under the engine terms; f is the channels' mean transmittance.
TEST(Fog, AtmosphericPerChannel) {
  Fog f = make(FogType::kAtmospheric);
  f.color = {0.8, 0.7, 0.6};
  f.extinction = {0.01, 0.02, 0.05};
  f.inscattering = {0.005, 0.02, 0.04};
  const glm::dvec3 obj(0.3, 0.5, 0.2);
  for (double d : {0.0, 1.0, 30.0, 400.0}) {
    const glm::dvec3 t = transmittance(f, 0, 0, d), s = scattered(f, 0, 0, d);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(t[c], std::exp(-f.extinction[c] * d), 1e-15);
      EXPECT_NEAR(s[c], f.color[c] * (1 - std::exp(-f.inscattering[c] * d)), 1e-15);
    }
    EXPECT_NEAR(factor(f, d), (t.r + t.g + t.b) / 3, 1e-15);
    const glm::dvec3 c = shade(f, obj, {0, 0, 0}, {0, 0, -d});
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(c[k], obj[k] * t[k] + s[k], 1e-15);
  }
  f.startDistance = 10;
  f.maxOpacity = 0.5;
  f.cutoffDistance = 300;
  for (double d : {5.0, 50.0, 299.0, 301.0}) {
    const glm::dvec3 t = transmittance(f, 0, 0, d), s = scattered(f, 0, 0, d);
    for (int c = 0; c < 3; ++c) {
      const double dd = std::max(0.0, d - 10);
      const bool cut = d > 300;
      EXPECT_NEAR(t[c], cut ? 1.0 : std::max(std::exp(-f.extinction[c] * dd), 0.5), 1e-15) << d;
      EXPECT_NEAR(s[c], cut ? 0.0 : f.color[c] * std::min(1 - std::exp(-f.inscattering[c] * dd), 0.5), 1e-15) << d;
    }
  }
  // Large tables (filled by a recurrence along the row) hold f, T and S to within one unit in
  // the last place of the stored float, through the start, the opacity cap and the cutoff.
  {
    TableOptions big = linear();
    big.size = 4096;
    auto tb = buildTable(f, big);
    ASSERT_TRUE(tb.ok());
    const Table& tab = tb.value();
    auto ulp = [](double x) {
      const float v = static_cast<float>(x);
      return double(std::nextafter(v, INFINITY) - v);
    };
    size_t off = 0;
    for (size_t i = 0; i < tab.width; ++i) {
      const double d = i + 1 == tab.width
                           ? tab.rangeEnd
                           : tab.rangeStart + (tab.rangeEnd - tab.rangeStart) * double(i) / double(tab.width - 1);
      const double fd = factorAtElevation(f, 0, 0, d);
      const glm::dvec3 tr = transmittance(f, 0, 0, d), sc = scattered(f, 0, 0, d);
      EXPECT_LE(std::fabs(tab.factor[i] - static_cast<float>(fd)), ulp(fd)) << d;
      off += tab.factor[i] != static_cast<float>(fd);
      for (int c = 0; c < 3; ++c) {
        EXPECT_LE(std::fabs(tab.transmittanceRgb[3 * i + size_t(c)] - static_cast<float>(tr[c])), ulp(tr[c])) << d;
        EXPECT_LE(std::fabs(tab.scatteredRgb[3 * i + size_t(c)] - static_cast<float>(sc[c])), ulp(sc[c])) << d;
      }
    }
    EXPECT_LE(off, tab.width / 100) << "entries one float step off";
  }
  // Where the last varying channel completes: ln 255 over the smallest positive coefficient.
  Fog g = make(FogType::kAtmospheric);
  g.extinction = {0, 0.02, 0.1};
  g.inscattering = {0, 0, 0.05};
  EXPECT_NEAR(completeDistance(g), std::log(255.0) / 0.02, 1e-9);
  g.extinction = g.inscattering = glm::dvec3(0);
  EXPECT_EQ(completeDistance(g), kInf);
  g.extinction = {1e300, 0, 0};
  EXPECT_EQ(transmittance(g, 0, 0, kInf).r, 0.0);
  EXPECT_EQ(transmittance(g, 0, 0, kInf).g, 1.0);  // no extinction: never dims, even at infinity
  g.extinction = {0.1, -1, 0};
  ASSERT_TRUE(validate(g));
  EXPECT_EQ(validate(g)->field, "/extinction/1");
  // Tables carry T and S per channel, exactly.
  TableOptions o = linear();
  o.size = 33;
  auto t = buildTable(f, o);
  ASSERT_TRUE(t.ok());
  ASSERT_EQ(t.value().transmittanceRgb.size(), 3u * 33);
  for (size_t i = 0; i < 33; ++i) {
    const double d = t.value().rangeEnd * double(i) / 32;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(t.value().transmittanceRgb[3 * i + size_t(c)], transmittance(f, 0, 0, d)[c], 1e-7);
      EXPECT_NEAR(t.value().scatteredRgb[3 * i + size_t(c)], scattered(f, 0, 0, d)[c], 1e-7);
    }
  }
}

// X3D's visibilityRange 0 turns the fog off: no distance completes it, and the error names that
// parameter rather than the range no distance reaches; with a range the table is all clear.
TEST(Fog, OffX3dFogNamesItsVisibilityRange) {
  for (FogType type : {FogType::kX3dLinear, FogType::kX3dExponential}) {
    Fog f = make(type);
    f.visibilityRange = 0;
    auto t = buildTable(f, linear());
    ASSERT_FALSE(t.ok());
    EXPECT_EQ(t.error().field, "/visibilityRange");
    EXPECT_EQ(t.error().kind, effects::ErrorKind::kUnsatisfiable);
    TableOptions o = linear();
    o.rangeEnd = 10.0;
    o.size = 4;
    t = buildTable(f, o);
    ASSERT_TRUE(t.ok());
    for (float v : t.value().transmittanceRgb) EXPECT_EQ(v, 1.0f);
  }
}

TEST(Fog, Validation) {
  Fog f = make(FogType::kX3dLinear);
  f.visibilityRange = -1;
  ASSERT_TRUE(validate(f));
  EXPECT_EQ(validate(f)->field, "/visibilityRange");
  f.visibilityRange = std::nan("");
  EXPECT_EQ(validate(f)->field, "/visibilityRange");
  f = make(FogType::kGlLinear);
  f.end = f.start;
  EXPECT_EQ(validate(f)->field, "/end");
  f = make(FogType::kDistanceGaussian);
  f.peak = 0;
  EXPECT_EQ(validate(f)->field, "/peak");
  f = make(FogType::kHeight);
  f.density = kInf;
  EXPECT_EQ(validate(f)->field, "/density");
  f = make(FogType::kGlExp);
  f.color = {0.5, 1.5, 0};
  EXPECT_EQ(validate(f)->field, "/color/1");
}

TEST(Fog, RegionsInnermostWinsAndBordersAreInside) {
  std::vector<Region> regions(3);
  regions[0].shape = Region::Shape::kBox;
  regions[0].min = {-10, -10, -10};
  regions[0].max = {10, 10, 10};
  regions[1].shape = Region::Shape::kSphere;
  regions[1].center = {0, 0, 0};
  regions[1].radius = 2;
  regions[2] = regions[1];  // same volume: the earlier one wins
  EXPECT_EQ(regionAt(regions, {0, 0, 0}), 1);
  EXPECT_EQ(regionAt(regions, {2, 0, 0}), 1);  // on the sphere's surface
  EXPECT_EQ(regionAt(regions, {5, 0, 0}), 0);
  EXPECT_EQ(regionAt(regions, {10, 10, 10}), 0);  // box corner
  EXPECT_EQ(regionAt(regions, {10.001, 0, 0}), -1);
  EXPECT_EQ(regionAt({}, {0, 0, 0}), -1);
}

TEST(Fog, TableErrorShrinksWithSize) {
  for (FogType t : kAll) {
    Fog f = make(t);
    double prev = 1e9;
    for (size_t n : {16, 64, 256, 1024}) {
      TableOptions o = linear();
      o.size = n;
      o.elevations = t == FogType::kHeight ? 16 : 0;
      auto table = buildTable(f, o);
      ASSERT_TRUE(table.ok()) << table.error().message;
      double e = table.value().maxError;
      EXPECT_TRUE(std::isfinite(e));
      EXPECT_LE(e, prev + 1e-7) << toString(t) << " n=" << n;  // float storage floor ~6e-8
      if (t != FogType::kX3dLinear && t != FogType::kGlLinear && t != FogType::kHeight) {
        EXPECT_LT(e, prev) << toString(t) << " n=" << n;
      }
      prev = e;
    }
  }
}

TEST(Fog, SmallestSizeForErrorMeetsIt) {
  for (FogType t : kAll) {
    for (double target : {1e-2, 1e-3, 1e-4}) {
      // A 2-D height table reaches ~4e-4 at the 256x256 entry limit.
      if (t == FogType::kHeight && target < 1e-3) continue;
      Fog f = make(t);
      TableOptions o = linear();
      o.size = 0;
      o.maxError = target;
      auto table = buildTable(f, o);
      ASSERT_TRUE(table.ok()) << toString(t) << " " << table.error().message;
      EXPECT_LE(table.value().maxError, target) << toString(t);
      if (table.value().width > 2 && t != FogType::kHeight && t != FogType::kX3dLinear && t != FogType::kGlLinear) {
        TableOptions smaller = o;
        smaller.size = table.value().width - 1;
        EXPECT_GT(buildTable(f, smaller).value().maxError, target) << toString(t) << " not minimal";
      }
    }
  }
}

// Example 08's fog (examples/08-sunset-fog.json) and the steep single layer of issue 47.
Fog sunsetFog() {
  Fog f;
  f.type = FogType::kHeight;
  f.color = {0.42, 0.36, 0.42};
  f.density = 0.012;
  f.heightFalloff = 0.06;
  f.startDistance = 3;
  f.maxOpacity = 0.97;
  f.secondLayer = HeightLayer{0.05, 0.9, 0.0};
  Directional d;
  d.color = {0.2, 0.1, 0.04};
  d.direction = {0.02, 0.06, -1};
  d.g = 0.55;
  d.startDistance = 10;
  f.directional = d;
  return f;
}
Fog steepFog() {
  Fog f;
  f.type = FogType::kHeight;
  f.density = 0.05;
  f.heightFalloff = 0.2;
  return f;
}

// A warped table looked up as docs/using/fog.md does it (v by asinh, u over the row's span,
// bilinear between entries), written here from the formulas, not through table.cpp's sampler.
double warpedLookup(const Table& t, const std::vector<float>& values, double start, double y, double d) {
  const WarpedAxes& a = t.warped;
  const double v = 0.5 + std::asinh(a.rowK * y) / (2.0 * std::asinh(a.rowK));
  const double span = warpedSpan(a, y, start);
  const double u = span > 0.0 ? std::clamp((d - start) / span, 0.0, 1.0) : 1.0;
  const double x = u * double(t.width - 1), yy = v * double(t.height - 1);
  const size_t i = std::min(size_t(x), t.width - 2), j = std::min(size_t(yy), t.height - 2);
  const double fx = x - double(i), fy = yy - double(j);
  auto at = [&](size_t jj, size_t ii) { return double(values[jj * t.width + ii]); };
  return (at(j, i) * (1 - fx) + at(j, i + 1) * fx) * (1 - fy) + (at(j + 1, i) * (1 - fx) + at(j + 1, i + 1) * fx) * fy;
}

// The largest lookup error at random rays and distances (half of them within 0.05 of the
// horizon, where rows are dense): an estimate that does not share the table's own sampling.
double randomLookupError(const Fog& f, const Table& t, double cameraHeight, int n) {
  std::mt19937 rng(47);
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  double worst = 0.0;
  for (int k = 0; k < n; ++k) {
    const double y = k % 2 ? -1.0 + 2.0 * unit(rng) : -0.05 + 0.1 * unit(rng);
    const double d = t.rangeEnd * unit(rng);
    worst = std::max(worst, std::fabs(warpedLookup(t, t.factor, t.warped.factorStart, y, d) -
                                      factorAtElevation(f, cameraHeight, y, d)));
    if (!t.inscatter.empty())
      worst = std::max(worst, std::fabs(warpedLookup(t, t.inscatter, t.warped.inscatterStart, y, d) -
                                        inscatterWeight(f, cameraHeight, y, d)));
  }
  return worst;
}

TEST(Fog, WarpedHeightTablesMeetAHundredthAt64x32) {
  struct Case {
    const char* name;
    Fog fog;
    double cameraHeight;
    double linearError;  // below the 64 x 32 linear table's error (0.485 sunset, 0.0139 steep)
  };
  for (const Case& c : {Case{"sunset", sunsetFog(), 1.7, 0.4}, Case{"steep", steepFog(), 2.0, 0.0139}}) {
    TableOptions o = linear();
    o.size = 64;
    o.elevations = 32;
    o.cameraHeight = c.cameraHeight;
    auto linear = buildTable(c.fog, o);
    ASSERT_TRUE(linear.ok());
    EXPECT_GT(linear.value().maxError, c.linearError) << c.name;
    o.layout = TableOptions::Layout::kWarped;
    o.elevations = 0;  // warped: half the columns
    auto warped = buildTable(c.fog, o);
    ASSERT_TRUE(warped.ok()) << warped.error().message;
    const Table& t = warped.value();
    EXPECT_EQ(t.height, 32u) << c.name;
    EXPECT_LE(t.maxError, 0.01) << c.name;
    // The reported error against an estimate it was not computed with.
    const double measured = randomLookupError(c.fog, t, c.cameraHeight, 40000);
    EXPECT_LE(measured, t.maxError * 1.25 + 1e-6) << c.name << ": reported " << t.maxError;
    EXPECT_GT(measured, t.maxError * 0.5) << c.name << ": reported " << t.maxError << " is far above the lookup's";
  }
}

TEST(Fog, WarpedTablesOfEachConventionAndTheSmallestForAnError) {
  for (Convention conv : {Convention::kEffectd, Convention::kFilament, Convention::kUnreal}) {
    Fog f = steepFog();
    f.convention = conv;
    f.startDistance = 4;
    TableOptions o = linear();
    o.layout = TableOptions::Layout::kWarped;
    o.cameraHeight = 2;
    o.maxError = 0.01;
    auto t = buildTable(f, o);
    ASSERT_TRUE(t.ok()) << toString(conv) << t.error().message;
    EXPECT_LE(t.value().maxError, 0.01) << toString(conv);
    EXPECT_EQ(t.value().height, tableRows(o, t.value().width));
    EXPECT_LT(t.value().width * t.value().height, 64u * 32u) << toString(conv);
    EXPECT_LE(randomLookupError(f, t.value(), 2, 20000), t.value().maxError * 1.25 + 1e-6) << toString(conv);
    TableOptions smaller = o;
    smaller.maxError = 0;
    smaller.size = t.value().width - 1;
    EXPECT_GT(buildTable(f, smaller).value().maxError, 0.01) << toString(conv) << " not minimal";
  }
}

TEST(Fog, WarpedAxesStayFiniteOnStiffFogs) {
  // Dense, thin, steep, flat, a camera far below and far above its layer, no opacity at all.
  struct Case {
    double density, falloff, base, camera, maxOpacity;
  };
  for (const Case& c :
       {Case{50, 5, 0, 0, 1}, Case{1e-9, 0.01, 0, 0, 1}, Case{0.05, 50, 0, 2, 1}, Case{0.05, 0, 0, 2, 1},
        Case{0.05, 0.2, 0, -3000, 1}, Case{0.05, 0.2, 0, 3000, 1}, Case{0.05, 0.2, 0, 2, 0}}) {
    Fog f = steepFog();
    f.density = c.density;
    f.heightFalloff = c.falloff;
    f.maxOpacity = c.maxOpacity;
    TableOptions o = linear();
    o.layout = TableOptions::Layout::kWarped;
    o.size = 64;
    o.cameraHeight = c.camera;
    o.rangeEnd = 1000.0;
    auto t = buildTable(f, o);
    ASSERT_TRUE(t.ok()) << t.error().message;
    const WarpedAxes& a = t.value().warped;
    for (double v : {a.rowK, a.kappa, a.lambda, a.falloff, t.value().maxError})
      EXPECT_TRUE(std::isfinite(v)) << c.density;
    for (float x : t.value().factor) ASSERT_TRUE(x >= 0.0f && x <= 1.0f) << c.density << " " << c.falloff;
    EXPECT_LE(randomLookupError(f, t.value(), c.camera, 4000), t.value().maxError * 1.25 + 1e-6)
        << c.density << " " << c.falloff << " " << c.camera;
  }
}

TEST(Fog, TableRangesAndLimits) {
  Fog f = make(FogType::kDistanceExp2);
  f.distanceCoefficient = 0;
  TableOptions o = linear();
  o.size = 8;
  auto t = buildTable(f, o);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().kind, ErrorKind::kUnsatisfiable);
  o.rangeEnd = 10;
  t = buildTable(f, o);
  ASSERT_TRUE(t.ok());
  for (float w : t.value().factor) EXPECT_EQ(w, 1.0f);
  o.size = 100000;
  o.maxSize = 65536;
  t = buildTable(f, o);
  ASSERT_FALSE(t.ok());
  EXPECT_EQ(t.error().kind, ErrorKind::kLimitExceeded);
  // The default range ends where the fog is complete to 1/255.
  Fog e = make(FogType::kGlExp);
  o = linear();
  o.size = 64;
  t = buildTable(e, o);
  ASSERT_TRUE(t.ok());
  EXPECT_NEAR(t.value().factor.back(), 1.0 / 255, 1e-6);
}

// Issue 59's table: samples across the range of double, each against its closed form. Before
// the scaled lengths (glm::length squares the components) these gave 1, 1 / 0, 0 / 0, 1, 1 / 1 / 0.
TEST(Fog, SamplesAcrossTheRangeOfDouble) {
  auto at = [](const Fog& f, glm::dvec3 point, glm::dvec3 camera = glm::dvec3(0)) {
    return sampleAt(f, {}, camera, point).factor;
  };
  Fog e = make(FogType::kGlExp);
  e.density = 1e300;
  EXPECT_NEAR(at(e, {1e-300, 0, 0}), std::exp(-1.0), 1e-12);
  EXPECT_NEAR(at(e, {0, 0, -2e-300}), std::exp(-2.0), 1e-12);
  Fog e2 = make(FogType::kGlExp2);
  e2.density = 1e-200;
  EXPECT_NEAR(at(e2, {1e200, 0, 0}), std::exp(-1.0), 1e-12);
  EXPECT_NEAR(at(e2, {0, 3e199, 4e199}), std::exp(-0.25), 1e-12);  // |p| by the scaled length: 5e199
  Fog h = make(FogType::kHeight);
  h.density = 0.05;
  h.heightFalloff = 0.2;
  h.baseHeight = 0;
  for (double d : {1e150, 1e160, 1e200}) EXPECT_EQ(at(h, {d, 0, 0}), 0.0) << d;  // level rays through the layer
  h.density = 1e170;
  EXPECT_NEAR(at(h, {1e-170, 0, 0}), std::exp(-1.0), 1e-12);
  Fog dx = make(FogType::kDistanceExp2);
  dx.distanceCoefficient = 5e-324;  // the smallest denormal, 4.94e-324
  for (double d : {5e161, 1e162, 2e162}) {
    const double expected = std::exp(-std::exp(std::log(4.9406564584124654e-324) + 2 * std::log(d)));
    EXPECT_NEAR(at(dx, {0, 0, d}), expected, 1e-12 + 1e-9 * expected) << d;
    EXPECT_GT(at(dx, {0, 0, d}), 0.0) << d;
  }
  // Points on opposite sides at +-1e308: the distance (2e308) is beyond the largest double and
  // counts as infinite; e^(-1e-300 * 2e308) is 0 as that says, and nothing is NaN.
  Fog g = make(FogType::kGlExp);
  g.density = 1e-300;
  EXPECT_EQ(at(g, {1e308, 0, 0}, {-1e308, 0, 0}), 0.0);
  EXPECT_EQ(sampleAt(h, {}, {-1e308, 0, 0}, {1e308, 1, 0}).factor, 0.0);
}

TEST(Fog, RegionsOfExtremeSizeHoldWhatTheyShould) {
  Region big, tiny;
  big.shape = tiny.shape = Region::Shape::kSphere;
  big.radius = 1e200;    // radius^2 overflows
  tiny.radius = 1e-200;  // radius^2 underflows
  EXPECT_EQ(regionAt({big}, {1e199, 0, 0}), 0);
  EXPECT_EQ(regionAt({big}, {1e250, 0, 0}), -1);
  EXPECT_EQ(regionAt({tiny}, {5e-201, 0, 0}), 0);
  EXPECT_EQ(regionAt({tiny}, {2e-200, 0, 0}), -1);
  EXPECT_EQ(regionAt({big, tiny}, {0, 0, 0}), 1);  // the innermost, by log volume
  EXPECT_LT(logVolume(tiny), logVolume(big));
}

// A falloff down in the denormals: 1 / falloff is beyond the doubles, so the warped axes are the
// uniform fog's (finite, no infinite lambda), and the table is exp(-a d) on every row.
TEST(Fog, WarpedAxesOfADenormalFalloffAreFinite) {
  Fog f = make(FogType::kHeight);
  f.density = 0.05;
  f.heightFalloff = 5e-324;
  const WarpedAxes a = warpedAxes(f, 2, 0, 100);
  for (double v : {a.rowK, a.falloff, a.kappa, a.lambda, a.end}) EXPECT_TRUE(std::isfinite(v));
  TableOptions o;  // the default, warped
  o.size = 16;
  o.cameraHeight = 2;
  auto t = buildTable(f, o);
  ASSERT_TRUE(t.ok());
  EXPECT_LT(t.value().maxError, 0.02);  // 16 entries of exp(-0.05 d) to completeness: h^2 a^2 / 8 = 0.017
}

// A camera so far above the layer that its density there is e^-300 of the surface's: kappa, the
// scale of a downward row's span, would be beyond any float. The rows stay warped, their columns
// even (kappa 0), so that every downward row covers the whole range and meets the fog where it
// is; kappa clamped instead ended those rows hundreds of metres short, held at f = 1 to the end
// (maxError 1). The front a high camera looks down on is a few metres deep, finer than 64 even
// columns: the table's measured maxError says so (0.75), and a larger table is the remedy.
TEST(Fog, WarpedTableFromFarAboveTheLayerReachesTheFog) {
  Fog f = make(FogType::kHeight);
  f.density = 0.05;
  f.heightFalloff = 0.5;
  f.baseHeight = 0;
  TableOptions o;  // the default, warped
  o.size = 64;
  o.cameraHeight = 600;
  o.rangeEnd = 4000;
  const WarpedAxes a = warpedAxes(f, o.cameraHeight, 0, *o.rangeEnd);
  EXPECT_EQ(a.kappa, 0.0);
  auto t = buildTable(f, o);
  ASSERT_TRUE(t.ok());
  EXPECT_LT(t.value().maxError, 0.9);
  // Every downward row whose ray is fogged by the range's end says so in its last column.
  const Table& table = t.value();
  int fogged = 0;
  for (size_t r = 0; r < table.height; ++r) {
    const double y = warpedRowY(a, double(r) / double(table.height - 1));
    if (factorAtElevation(f, o.cameraHeight, y, *o.rangeEnd) > 0.01) continue;
    ++fogged;
    EXPECT_LT(table.factor[r * table.width + table.width - 1], 0.02) << "row " << r << ", y " << y;
  }
  EXPECT_GE(fogged, 3);
}

}  // namespace
}  // namespace effects::fog
