// HEIGHT fog in the engines' conventions (fog.h, Convention): each engine's shader formula, term
// for term, over effectd's parameters. Sources and the mapping of parameters: docs/effects.md §2.4;
// tests/fog_engines/ holds independent transcriptions the tests compare with.
#include <algorithm>
#include <cmath>
#include <limits>

#include "effects/fog.h"
#include "log_mean.h"

namespace effects::fog {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const double kLn2 = std::log(2.0);

using detail::logG;
using detail::mulZero;

// ---- Filament (shaders/src/surface_fog.fs, fog()) ----------------------------------------------
// Its mean density over the whole ray [0, d]: the density at the camera, times the mean of the
// exponential along the ray unless the ray is near level (|b v_y| <= 0.00125, v_y = d dirY).
constexpr double kFilamentNearLevel = 0.00125;

// The optical depth m * max(d - from, 0); at d = +inf (the sky) the limit of a far ray.
double filamentDepth(const Fog& fog, double originY, double dirY, double d, double from) {
  const double a = fog.density, b = fog.heightFalloff;
  if (a == 0.0 || !(d > from)) return 0.0;
  const double logDensity = std::log(a) - b * (originY - fog.baseHeight);
  if (std::isinf(d)) {
    if (b * dirY > 0.0) {  // sigma / (b dirY): what its sky, drawn at 1e19, tends to
      const double l = logDensity - std::log(b * dirY);
      return l > 709.0 ? kInf : std::exp(l);
    }
    return kInf;
  }
  const double fh = b * dirY * d;
  const double l = logDensity + (std::fabs(fh) > kFilamentNearLevel ? logG(fh) : 0.0) + std::log(d - from);
  return l > 709.0 ? kInf : std::exp(l);
}

// ---- Unreal (HeightFogCommon.ush, GetExponentialHeightFog; FogRendering.cpp) -------------------
// In base 2 per world unit: density a / ln2^2, falloff b / ln2 (the component's FogDensity and
// FogHeightFalloff over 1000, in centimetres).
constexpr double kUnrealObserverAbove = 65536.0;  // the observer's height clamp above the lowest layer
constexpr double kUnrealTaylorBelow = 0.01;       // FLT_EPSILON2: below it the line integral's Taylor term

struct UnrealLayer {
  double density, falloff, height;
};

int unrealLayers(const Fog& fog, UnrealLayer out[2]) {
  int n = 0;
  out[n++] = {fog.density / (kLn2 * kLn2), fog.heightFalloff / kLn2, fog.baseHeight};
  if (const auto& l = fog.secondLayer) out[n++] = {l->density / (kLn2 * kLn2), l->heightFalloff / kLn2, l->baseHeight};
  return n;
}

// CalculateLineIntegralShared: the density at the ray's start times (1 - 2^-F) / F, F = falloff * rise.
double unrealLineIntegral(double falloff, double rise, double originTerms) {
  const double f = std::max(-127.0, falloff * rise);
  if (std::fabs(f) > kUnrealTaylorBelow) return originTerms * -std::expm1(-f * kLn2) / f;
  return originTerms * (kLn2 - 0.5 * kLn2 * kLn2 * f);
}

struct UnrealRay {
  double shared = 0;     // the summed line integrals per unit of ray length
  double rayLength = 0;  // from the start distance to the point (negative: the point is nearer)
  double length = 0;     // from the (clamped) observer to the point
};

UnrealRay unrealRay(const Fog& fog, double originY, double dirY, double distance) {
  UnrealLayer layers[2];
  const int n = unrealLayers(fog, layers);
  const double observer = observerHeight(fog, originY);
  // The vector from the observer to the point: the camera's, lowered with the observer.
  const double horizontal = mulZero(distance, std::sqrt(std::max(0.0, 1.0 - dirY * dirY)));
  const double vy = mulZero(distance, dirY) + (originY - observer);
  UnrealRay r;
  r.length = std::hypot(horizontal, vy);
  r.rayLength = r.length;
  double rise = vy;
  // The density at the ray's start: the camera's (its exponent clamped to [-125, 126]), or
  // where the start distance puts it (its exponent at most 127).
  double originTerms[2];
  for (int i = 0; i < n; ++i)
    originTerms[i] = layers[i].density * std::exp2(std::clamp(-layers[i].falloff * (observer - layers[i].height), -125.0, 126.0));
  const bool far = std::isinf(distance);
  if (fog.startDistance > 0.0 && r.length > 0.0) {  // the ray from the exclusion distance on
    const double t = far ? 0.0 : fog.startDistance / r.length;
    const double startY = observer + t * vy;
    if (!far) {
      r.rayLength = (1.0 - t) * r.length;
      rise = vy - t * vy;
    }
    for (int i = 0; i < n; ++i)
      originTerms[i] = layers[i].density * std::exp2(-std::max(-127.0, layers[i].falloff * (startY - layers[i].height)));
  }
  if (far) {  // the sky: each layer's integral in the far limit, (1 - 2^-F) / F * L -> 1 / (falloff dirY)
    for (int i = 0; i < n; ++i) {
      if (originTerms[i] == 0.0) continue;
      r.shared += layers[i].falloff * dirY > 0.0 ? originTerms[i] / (layers[i].falloff * dirY) : kInf;
    }
    r.rayLength = 1.0;  // shared is the whole integral
    return r;
  }
  for (int i = 0; i < n; ++i) r.shared += unrealLineIntegral(layers[i].falloff, rise, originTerms[i]);
  return r;
}

// 2^-x saturated to [0, 1].
double unrealTransmittance(double x) { return std::clamp(std::exp2(-x), 0.0, 1.0); }

}  // namespace

double observerHeight(const Fog& fog, double eyeY) {
  if (fog.convention != Convention::kUnreal) return eyeY;
  UnrealLayer layers[2];
  const int n = unrealLayers(fog, layers);
  double observer = eyeY;
  for (int i = 0; i < n; ++i)
    if (layers[i].density > 0.0) observer = std::min(observer, layers[i].height + kUnrealObserverAbove);
  return observer;
}

double glowStart(const Fog& fog) {
  const double own = fog.directional ? fog.directional->startDistance : 0.0;
  switch (fog.convention) {
    case Convention::kFilament: return own;
    case Convention::kUnreal: return fog.startDistance + own;
    case Convention::kEffectd: break;
  }
  return std::max(fog.startDistance, own);
}

double engineFactor(const Fog& fog, double originY, double dirY, double distance) {
  if (fog.convention == Convention::kFilament) {
    if (distance < fog.startDistance || distance > fog.cutoffDistance) return 1.0;
    const double t = std::exp(-filamentDepth(fog, originY, dirY, distance, fog.startDistance));
    return std::max(t, 1.0 - fog.maxOpacity);  // opacity = min(1 - t, maximumOpacity)
  }
  const UnrealRay r = unrealRay(fog, originY, dirY, distance);
  if (r.length > fog.cutoffDistance) return 1.0;
  const double integral = r.shared == 0.0 ? 0.0 : r.shared * r.rayLength;
  return std::max(unrealTransmittance(integral), 1.0 - fog.maxOpacity);
}

double engineInscatterWeight(const Fog& fog, double originY, double dirY, double distance) {
  if (!fog.directional) return 0.0;
  if (fog.convention == Convention::kFilament) {
    // The whole fog, glow included, is drawn only from its start distance to its cutoff.
    if (distance < fog.startDistance || distance > fog.cutoffDistance) return 0.0;
    return -std::expm1(-filamentDepth(fog, originY, dirY, distance, fog.directional->startDistance));
  }
  const UnrealRay r = unrealRay(fog, originY, dirY, distance);
  if (r.length > fog.cutoffDistance || r.shared == 0.0) return 0.0;
  const double beyond = std::isinf(distance) ? 1.0 : std::max(r.rayLength - fog.directional->startDistance, 0.0);
  return 1.0 - unrealTransmittance(beyond > 0.0 ? r.shared * beyond : 0.0);
}

}  // namespace effects::fog
