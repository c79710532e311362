// effects/glow.h — the glow of a light seen through fog: the atmospheric point spread function.
//
// Source: Narasimhan & Nayar, "Shedding Light on the Weather" (CVPR 2003), the APSF of an
// isotropic point source seen at distance R through a homogeneous medium of extinction sigma:
//   I(T, mu) = sum_{m >= 0} (g_m(T) + g_{m+1}(T)) L_m(mu),   g_0 = 0,
//   g_m(T)  = e^(-beta_m T - alpha_m ln T),  alpha_m = m + 1,  beta_m = (2m + 1)/m (1 - q^(m-1)),
// T = sigma R the optical thickness, q the forward-scattering parameter (Henyey-Greenstein's g:
// 0 air, 0.7-0.8 haze, 0.85-0.9 fog, 0.9-1 rain), mu = cos theta, theta the angle between the
// direction looked in and the source, L_m the Legendre polynomials. docs/effects.md §5 holds
// the derivation of what is below and where the physics is simplified.
//
// What effectd adds, each stated where it is used:
//   - The series converges only for T > 1 (its terms go like T^-m). Its shape is taken at
//     max(T, kMinSeriesThickness); below, the light that reaches the eye unscattered, e^-T,
//     is the crisp core and only the scattered share 1 - e^-T is spread by the kernel, so the
//     halo fades out as T -> 0 (clear air: a delta).
//   - By the Legendre polynomials' orthogonality, I integrates over the sphere to 4 pi g_1 =
//     4 pi / T^2 (beta_1 = 0 for every q): kernels are normalised by that closed form.
//   - Terms are summed in log space with a running scale, so that T = 1e4 (every g_m below
//     1e-8000) and q = 0 or 1 give finite shapes.
//
// Thread-safety: every function is pure and reentrant.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "effects/common.h"
#include "effects/export.h"
#include "effects/fog.h"

EFFECTS_API_BEGIN
namespace effects::glow {

inline constexpr double kDefaultForwardScattering = 0.9;  // Narasimhan & Nayar's "fog"
inline constexpr double kMinSeriesThickness = 1.05;        // the shape's T floor (see above)
inline constexpr double kMaxThickness = 1e4;               // beyond: the shape is the T -> inf limit to 1e-300
inline constexpr double kSeriesTolerance = 1e-12;          // relative truncation of the series

struct Medium {
  double thickness = 2.0;                               // T = sigma R >= 0
  double forwardScattering = kDefaultForwardScattering;  // q in [0, 1]
};
// Field errors name the member: "/opticalThickness", "/forwardScattering".
[[nodiscard]] std::optional<Error> validate(const Medium& medium);

// The T the series' shape is evaluated at: clamp(T, kMinSeriesThickness, kMaxThickness).
double shapeThickness(const Medium& medium);

// The reference: the series at the angles (radians, in [0, pi]) for the shape's T, each divided
// by the sphere integral 4 pi / T^2: the kernel per steradian, integrating to 1 over the
// sphere. Summed until the next terms' geometric bound is below kSeriesTolerance of the sum.
struct Profile {
  std::vector<double> angles, values;
  int terms = 0;           // the most terms any angle needed
  double truncation = 0;   // the largest relative tail bound at stopping
};
Profile apsf(const Medium& medium, const std::vector<double>& angles);

// A sum of Gaussians in the angle theta (radians), per steradian in the small-angle sense:
//   K(theta) = sum_k weight_k e^(-theta^2 / (2 sigma_k^2)) / (2 pi sigma_k^2).
// A renderer draws it as a cascade of separable blurs (render/passes/lightning.cpp).
struct Gaussian {
  double weight = 0, sigma = 0;
};
double gaussiansAt(const std::vector<Gaussian>& gaussians, double angle);

// The ways a kernel is given, fastest to exact. kSeries is the reference.
enum class Method { kGaussian, kGaussians2, kGaussians3, kTable, kSeries };
const char* toString(Method method);  // "gaussian", "gaussians-2", "gaussians-3", "table", "series"
std::optional<Method> methodFromString(const std::string& name);

struct KernelOptions {
  Method method = Method::kGaussians3;
  double maxAngle = 1.5707963267948966;  // the kernel's extent (radians, in (0, pi]): a screen sees < pi/2
  int samples = 64;                      // the radial table's entries (kTable, kSeries), 2 ... 4096
  bool measureError = true;              // against the series over [0, maxAngle]
};

struct Kernel {
  Medium medium;
  double shapeThickness = 0;  // the T the shape was taken at
  double direct = 1;          // e^-T: the share that reaches the eye unscattered (the crisp core)
  double scattered = 0;       // 1 - e^-T: the share the kernel spreads
  Method method = Method::kGaussians3;
  std::vector<Gaussian> gaussians;    // kGaussian*, fitted to the series over [0, maxAngle]
  std::vector<double> angles, values;  // kTable, kSeries: the radial table (values per steradian)
  double maxAngle = 0;
  double haloRadius = 0;  // the angle within which half of the kernel's light within maxAngle falls
  // The share of the light put in the wrong place, by the series on a 4x denser grid:
  // integral over [0, maxAngle] of |K - K_series| dOmega (0: exact; 2 at most).
  std::optional<double> misplaced;
  Stats stats;
};
Result<Kernel> kernel(const Medium& medium, const KernelOptions& options = {});

// The kernel given by `method`, at `angle` (per steradian); linear in angle between table entries.
double kernelAt(const Kernel& kernel, double angle);

// The optical thickness from `eye` to `point` through a fog (the innermost region's, as
// fog::sampleAt picks it): T = -ln of the channels' mean transmittance, so that e^-T is what
// the fog lets through, finite (at most 745, where e^-T underflows).
double thicknessAlong(const fog::Fog& global, const std::vector<fog::Region>& regions, const glm::dvec3& eye,
                      const glm::dvec3& point);
// The medium's q: the fog's directional Henyey-Greenstein g when it has one (clamped to [0, 1]),
// else kDefaultForwardScattering.
double forwardScatteringOf(const fog::Fog& fog);

// The independent check: photons from an isotropic point source at the centre of a unit sphere
// in an infinite, non-absorbing medium of extinction T with Henyey-Greenstein scattering (g = q),
// every crossing of the sphere counted with weight 1/|mu| in its angle's bin (radiance), the
// unscattered photons in the first. Photons are followed until `escape` radii out (those that
// would come back from farther are lost: a bias below 1/escape of the returning light).
struct MonteCarloOptions {
  int64_t photons = 200000;
  int bins = 30;           // equal in theta over [0, pi]
  double escape = 20.0;
  uint64_t seed = 1;
};
struct MonteCarlo {
  std::vector<double> edges;            // bins + 1 angles (radians)
  std::vector<double> values, errors;   // per steradian, normalised over the sphere; one standard error
  double directShare = 0;               // photons reaching the sphere unscattered (e^-T expected)
  int64_t photons = 0;
};
MonteCarlo monteCarlo(const Medium& medium, const MonteCarloOptions& options = {});
// The series averaged over each of those bins (for comparison with monteCarlo's values).
std::vector<double> apsfBinned(const Medium& medium, const std::vector<double>& edges);

}  // namespace effects::glow
EFFECTS_API_END
