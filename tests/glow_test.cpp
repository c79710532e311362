// The APSF (effects/glow.h): the series against closed forms of its own limits and against an
// independent photon simulation; the fitted kernels against the series.
#include <cmath>
#include <numbers>

#include <gtest/gtest.h>

#include <effects/glow.h>

namespace {

using namespace effects::glow;
constexpr double kPi = std::numbers::pi;

// The integral over the sphere of the series' kernel (Gauss-Legendre-free: 4000 rings).
double sphereIntegral(const Medium& m) {
  std::vector<double> angles;
  const int n = 4000;
  for (int i = 0; i < n; ++i) angles.push_back((i + 0.5) * kPi / n);
  const Profile p = apsf(m, angles);
  double sum = 0;
  for (int i = 0; i < n; ++i) sum += p.values[size_t(i)] * 2 * kPi * std::sin(angles[size_t(i)]) * kPi / n;
  return sum;
}

TEST(Apsf, IntegratesToOneOverTheSphere) {
  // By orthogonality only L_0 survives: 4 pi g_1, the normaliser. Summed, not assumed.
  for (double t : {1.05, 1.5, 3.0, 20.0, 1e4})
    for (double q : {0.0, 0.5, 0.9, 0.99, 1.0}) EXPECT_NEAR(sphereIntegral({t, q}), 1.0, 2e-3) << t << " " << q;
}

TEST(Apsf, AllForwardIsTheLegendreGeneratingFunction) {
  // q = 1: beta_m = 0, g_m = T^-(m+1), and sum t^m L_m = 1/sqrt(1 - 2 mu t + t^2) gives
  // I = T^-2 G(1/T) + T^-1 (G(1/T) - 1), over 4 pi T^-2.
  for (double t : {1.05, 1.3, 2.0, 7.0})
    for (double angle : {0.0, 0.01, 0.3, 1.0, 2.0, 3.14}) {
      const double mu = std::cos(angle), x = 1 / t, g = 1 / std::sqrt(1 - 2 * mu * x + x * x);
      const double closed = (g / (t * t) + (g - 1) / t) * t * t / (4 * kPi);
      const double series = apsf({t, 1.0}, {angle}).values[0];
      EXPECT_NEAR(series / closed, 1.0, 1e-9) << t << " " << angle;
    }
}

TEST(Apsf, DiffuseLimitIsOnePlusMu) {
  // T -> infinity: every g_m after g_1 falls like e^(-beta_m T): (1 + mu) / (4 pi), no underflow.
  for (double q : {0.0, 0.9})
    for (double t : {800.0, 1e4, 1e300}) {
      const Profile p = apsf({t, q}, {0.0, 1.0, 2.0, kPi});
      for (size_t i = 0; i < p.angles.size(); ++i) {
        ASSERT_TRUE(std::isfinite(p.values[i]));
        EXPECT_NEAR(p.values[i], (1 + std::cos(p.angles[i])) / (4 * kPi), 1e-12);
      }
    }
}

TEST(Apsf, NearTheSeriesEdgeStaysFinite) {
  // T below the floor takes the floor's shape; q = 0 (0^0 at m = 1) is finite.
  for (double t : {0.0, 1e-300, 0.5, 1.0, 1.05})
    for (double q : {0.0, 1e-300, 0.999999, 1.0}) {
      const Profile p = apsf({t, q}, {0.0, 0.5, kPi});
      for (double v : p.values) EXPECT_TRUE(std::isfinite(v) && v >= 0) << t << " " << q;
      EXPECT_LT(p.truncation, kSeriesTolerance);
    }
  EXPECT_EQ(apsf({0.2, 0.9}, {0.3}).values, apsf({kMinSeriesThickness, 0.9}, {0.3}).values);
  EXPECT_TRUE(validate({-1, 0.5}).has_value());
  EXPECT_TRUE(validate({1, 1.5}).has_value());
  EXPECT_TRUE(validate({NAN, 0.5}).has_value());
}

TEST(Apsf, HaloWidensWithThickness) {
  // The kernel's half-light radius grows with T at every q: strictly where the forward peak
  // is still there (q 0.9, 0.99); at q 0 and 0.5 it reaches the diffuse (1 + mu) limit by T 3-5,
  // after which it stays (on the 0.04-degree grid).
  for (double q : {0.0, 0.5, 0.9, 0.99}) {
    double previous = 0;
    for (double t : {1.05, 1.2, 1.5, 2.0, 3.0, 5.0, 10.0, 100.0}) {
      KernelOptions o;
      o.method = Method::kTable;
      o.samples = 512;
      const double r = kernel({t, q}, o).value().haloRadius;
      if (q >= 0.9)
        EXPECT_GT(r, previous) << "q " << q << " T " << t;
      else
        EXPECT_GE(r, previous) << "q " << q << " T " << t;
      previous = r;
    }
  }
}

TEST(Apsf, FittedKernelsConvergeOnTheSeries) {
  // More Gaussians misplace less light; the table is the closest.
  for (double t : {1.2, 2.0, 6.0}) {
    double previous = INFINITY;
    for (Method m : {Method::kGaussian, Method::kGaussians2, Method::kGaussians3}) {
      KernelOptions o;
      o.method = m;
      const Kernel k = kernel({t, 0.9}, o).value();
      ASSERT_TRUE(k.misplaced);
      EXPECT_LE(*k.misplaced, previous * 1.0001) << toString(m) << " T " << t;
      previous = *k.misplaced;
      for (const Gaussian& g : k.gaussians) EXPECT_TRUE(g.weight >= 0 && g.sigma > 0);
    }
    EXPECT_LT(previous, 0.02);
    KernelOptions o;
    o.method = Method::kTable;
    o.samples = 256;
    EXPECT_LT(*kernel({t, 0.9}, o).value().misplaced, 1e-3);
  }
  const Kernel k = kernel({0.3, 0.9}).value();
  EXPECT_NEAR(k.direct, std::exp(-0.3), 1e-15);
  EXPECT_NEAR(k.direct + k.scattered, 1.0, 1e-15);
}

TEST(ApsfMonteCarlo, UnscatteredShareIsBeerLambert) {
  MonteCarloOptions o;
  o.photons = 40000;
  for (double t : {0.5, 2.0}) {
    const MonteCarlo mc = monteCarlo({t, 0.9}, o);
    const double p = std::exp(-t), se = std::sqrt(p * (1 - p) / double(o.photons));
    EXPECT_NEAR(mc.directShare, p, 4 * se) << t;
  }
}

TEST(ApsfMonteCarlo, DeepIsotropicMediumMatchesDiffusion) {
  // Diffusion theory around a point source in a conservative medium: radiance ~ T (1 - g) + mu,
  // so the ratio of two angles' radiance is (T(1-g) + mu1) / (T(1-g) + mu2). Checked on the
  // bins at 60 and 120 degrees (away from the direct beam), T = 6, g = 0.
  MonteCarloOptions o;
  o.photons = 6000;
  o.bins = 6;
  o.escape = 30;
  const MonteCarlo mc = monteCarlo({6.0, 0.0}, o);
  // bins of 30 degrees: [60, 90) and [90, 120); their mean mu is +-0.25 (exactly: cos over the ring)
  const double muA = (std::cos(kPi / 3) + std::cos(kPi / 2)) / 2, muB = -muA;
  const double expected = (6 + muA) / (6 + muB), seen = mc.values[2] / mc.values[3];
  const double se = seen * std::hypot(mc.errors[2] / mc.values[2], mc.errors[3] / mc.values[3]);
  EXPECT_NEAR(seen, expected, 4 * se + 0.03) << "seen " << seen << " expected " << expected;
}

}  // namespace
