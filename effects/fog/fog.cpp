#include "effects/fog.h"
#include "log_mean.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

namespace effects::fog {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
const double kLn255 = std::log(255.0);  // -ln(1/255): complete to 8 bits

bool finite(double v) { return std::isfinite(v); }

using detail::expMinusCD2;
using detail::logG;
using detail::mulZero;

}  // namespace

const char* toString(FogType type) {
  switch (type) {
    case FogType::kX3dLinear: return "LINEAR";
    case FogType::kX3dExponential: return "EXPONENTIAL";
    case FogType::kGlLinear: return "GL_LINEAR";
    case FogType::kGlExp: return "GL_EXP";
    case FogType::kGlExp2: return "GL_EXP2";
    case FogType::kDistanceExp2: return "DISTANCE_EXP2";
    case FogType::kDistanceGaussian: return "DISTANCE_GAUSSIAN";
    case FogType::kHeight: return "HEIGHT";
    case FogType::kAtmospheric: return "ATMOSPHERIC";
  }
  return "?";
}

std::optional<FogType> fogTypeFromString(const std::string& name) {
  for (FogType t :
       {FogType::kX3dLinear, FogType::kX3dExponential, FogType::kGlLinear, FogType::kGlExp, FogType::kGlExp2,
        FogType::kDistanceExp2, FogType::kDistanceGaussian, FogType::kHeight, FogType::kAtmospheric}) {
    if (name == toString(t)) return t;
  }
  return std::nullopt;
}

const char* toString(Convention convention) {
  switch (convention) {
    case Convention::kEffectd: return "effectd";
    case Convention::kFilament: return "filament";
    case Convention::kUnreal: return "unreal";
  }
  return "?";
}

std::optional<Convention> conventionFromString(const std::string& name) {
  for (Convention c : {Convention::kEffectd, Convention::kFilament, Convention::kUnreal})
    if (name == toString(c)) return c;
  return std::nullopt;
}

std::optional<Error> validate(const Fog& fog) {
  if (fog.convention != Convention::kEffectd) {
    const std::string engine = fog.convention == Convention::kFilament ? "Filament" : "Unreal";
    if (fog.type != FogType::kHeight)
      return invalid("/convention", "an engine's convention is its height fog: use fogType HEIGHT");
    if (fog.convention == Convention::kFilament && fog.secondLayer)
      return invalid("/secondLayer", "Filament's fog has one layer");
    if (fog.directional && !fog.directional->exponent)
      return invalid("/directional/exponent",
                     engine + "'s glow lobe is max(cos theta, 0)^exponent: give exponent (g is effectd's lobe)");
  }
  for (int i = 0; i < 3; ++i) {
    if (!(fog.color[i] >= 0.0 && fog.color[i] <= 1.0))
      return invalid("/color/" + std::to_string(i), "must be in [0, 1]");
  }
  auto nonNegative = [](double v, const char* field) -> std::optional<Error> {
    if (!(v >= 0.0) || !finite(v)) return invalid(field, "must be a finite number >= 0");
    return std::nullopt;
  };
  std::optional<Error> mode;  // the mode's own parameters
  switch (fog.type) {
    case FogType::kX3dLinear:
    case FogType::kX3dExponential: mode = nonNegative(fog.visibilityRange, "/visibilityRange"); break;
    case FogType::kGlLinear:
      if (!finite(fog.start) || fog.start < 0.0) return invalid("/start", "must be a finite number >= 0");
      if (!finite(fog.end) || !(fog.end > fog.start)) return invalid("/end", "must be finite and greater than start");
      break;
    case FogType::kGlExp:
    case FogType::kGlExp2: mode = nonNegative(fog.density, "/density"); break;
    case FogType::kDistanceGaussian:
      if (!(fog.peak > 0.0 && fog.peak <= 1.0)) return invalid("/peak", "must be in (0, 1]");
      [[fallthrough]];
    case FogType::kDistanceExp2: mode = nonNegative(fog.distanceCoefficient, "/distanceCoefficient"); break;
    case FogType::kHeight:
      if (auto e = nonNegative(fog.density, "/density")) return e;
      if (auto e = nonNegative(fog.heightFalloff, "/heightFalloff")) return e;
      if (!finite(fog.baseHeight)) return invalid("/baseHeight", "must be finite");
      break;
    case FogType::kAtmospheric:
      for (int i = 0; i < 3; ++i) {
        if (auto e = nonNegative(fog.extinction[i], ("/extinction/" + std::to_string(i)).c_str())) return e;
        if (auto e = nonNegative(fog.inscattering[i], ("/inscattering/" + std::to_string(i)).c_str())) return e;
      }
      break;
  }
  if (mode) return mode;
  if (auto e = nonNegative(fog.startDistance, "/startDistance")) return e;
  if (!(fog.maxOpacity >= 0.0 && fog.maxOpacity <= 1.0)) return invalid("/maxOpacity", "must be in [0, 1]");
  if (!(fog.cutoffDistance > 0.0)) return invalid("/cutoffDistance", "must be > 0 (absent: no cutoff)");
  if (const auto& d = fog.directional) {
    for (int i = 0; i < 3; ++i)
      if (!(d->color[i] >= 0.0 && d->color[i] <= 1e6))
        return invalid("/directional/color/" + std::to_string(i), "must be in [0, 1e6]");
    const double len = detail::length(d->direction);
    if (!(len > 0.0) || !finite(len)) return invalid("/directional/direction", "must be a finite non-zero vector");
    if (!(d->g > -1.0 && d->g < 1.0)) return invalid("/directional/g", "must be in (-1, 1)");
    if (d->exponent && !(*d->exponent > 0.0 && *d->exponent <= 1e6))
      return invalid("/directional/exponent", "must be in (0, 1e6]");
    if (auto e = nonNegative(d->startDistance, "/directional/startDistance")) return e;
  }
  if (fog.secondLayer) {
    if (fog.type != FogType::kHeight) return invalid("/secondLayer", "only HEIGHT fog has a second layer");
    if (auto e = nonNegative(fog.secondLayer->density, "/secondLayer/density")) return e;
    if (auto e = nonNegative(fog.secondLayer->heightFalloff, "/secondLayer/heightFalloff")) return e;
    if (!finite(fog.secondLayer->baseHeight)) return invalid("/secondLayer/baseHeight", "must be finite");
  }
  return std::nullopt;
}

double heightOpticalDepth(double a, double b, double h, double originY, double dirY, double t) {
  if (a == 0.0 || t == 0.0) return 0.0;
  if (b == 0.0) return a * t;  // uniform density; a * inf = inf
  const double k = b * dirY;   // density along the ray: a e^{-b(oy-h)} e^{-k s}
  const double logBase = std::log(a) - b * (originY - h);
  if (std::isinf(t)) {
    if (k <= 0.0) return kInf;              // level or descending ray into ever denser fog
    double logTau = logBase - std::log(k);  // integral of e^{-k s} over [0, inf) = 1/k
    return logTau > 709.0 ? kInf : std::exp(logTau);
  }
  double logTau = logBase + std::log(t) + logG(k * t);
  return logTau > 709.0 ? kInf : std::exp(logTau);
}

double heightOpticalDepthMarched(double a, double b, double h, double originY, double dirY, double t, int steps) {
  const double dt = t / steps;
  double sum = 0.0;
  for (int i = 0; i < steps; ++i) {
    double y = originY + dirY * (i + 0.5) * dt;
    sum += a * std::exp(-b * (y - h));
  }
  return sum * dt;
}

namespace {

// The weight of the mode itself at distance d (start distance already taken off).
double modeFactor(const Fog& fog, double d) {
  switch (fog.type) {
    case FogType::kX3dLinear: {
      const double v = fog.visibilityRange;
      if (v <= 0.0) return 1.0;
      return d >= v ? 0.0 : (v - d) / v;
    }
    case FogType::kX3dExponential: {
      const double v = fog.visibilityRange;
      if (v <= 0.0) return 1.0;
      return d >= v ? 0.0 : std::exp(-d / (v - d));  // d/(v-d) -> +inf as d -> v: f -> 0
    }
    case FogType::kGlLinear: return std::clamp((fog.end - d) / (fog.end - fog.start), 0.0, 1.0);
    case FogType::kGlExp: return std::exp(-mulZero(fog.density, d));
    case FogType::kGlExp2: {
      double x = mulZero(fog.density, d);
      return std::exp(-x * x);
    }
    case FogType::kDistanceExp2: return expMinusCD2(fog.distanceCoefficient, d);  // seed 003 eqn 1
    case FogType::kDistanceGaussian:  // seed 003 eqn 2, parameterised (see header)
      return fog.peak * expMinusCD2(fog.distanceCoefficient, d);
    case FogType::kHeight: break;  // along a ray: factorAtElevation
    case FogType::kAtmospheric: {  // the channels' mean (per channel: transmittance)
      double sum = 0.0;
      for (int c = 0; c < 3; ++c) sum += std::exp(-mulZero(fog.extinction[c], d));
      return sum / 3.0;
    }
  }
  return 1.0;
}

// Optical depth of the height layers over the part [startDistance, distance] of the ray.
double heightDepth(const Fog& fog, double originY, double dirY, double distance) {
  const double s = std::min(fog.startDistance, distance);
  const double y = s > 0.0 ? originY + dirY * s : originY;
  const double t = distance - s;
  double tau = heightOpticalDepth(fog.density, fog.heightFalloff, fog.baseHeight, y, dirY, t);
  if (const auto& l = fog.secondLayer)
    tau += heightOpticalDepth(l->density, l->heightFalloff, l->baseHeight, y, dirY, t);
  return tau;
}

}  // namespace

double engineLimits(const Fog& fog, double distance, double f) {
  if (distance > fog.cutoffDistance) return 1.0;
  return std::max(f, 1.0 - fog.maxOpacity);
}

double factorAtElevation(const Fog& fog, double originY, double dirY, double distance) {
  if (fog.convention != Convention::kEffectd) return engineFactor(fog, originY, dirY, distance);
  if (fog.type != FogType::kHeight)
    return engineLimits(fog, distance, modeFactor(fog, std::max(0.0, distance - fog.startDistance)));
  return engineLimits(fog, distance, std::exp(-heightDepth(fog, originY, dirY, distance)));
}

double factor(const Fog& fog, double d) { return factorAtElevation(fog, fog.baseHeight, 0.0, d); }

namespace {

// ATMOSPHERIC: e^(-k d) per channel over the ray beyond the start, under the engine limits.
glm::dvec3 channelsLimited(const Fog& fog, const glm::dvec3& k, double distance) {
  const double d = std::max(0.0, distance - fog.startDistance);
  glm::dvec3 t;
  for (int c = 0; c < 3; ++c) t[c] = engineLimits(fog, distance, std::exp(-mulZero(k[c], d)));
  return t;
}

}  // namespace

glm::dvec3 transmittance(const Fog& fog, double originY, double dirY, double distance) {
  if (fog.type != FogType::kAtmospheric) return glm::dvec3(factorAtElevation(fog, originY, dirY, distance));
  return channelsLimited(fog, fog.extinction, distance);
}

glm::dvec3 scattered(const Fog& fog, double originY, double dirY, double distance) {
  if (fog.type != FogType::kAtmospheric) return (1.0 - factorAtElevation(fog, originY, dirY, distance)) * fog.color;
  // the in-scattered weight, capped like the opacity: 1 - engineLimits(1 - w)
  return (1.0 - channelsLimited(fog, fog.inscattering, distance)) * fog.color;
}

double inscatterWeight(const Fog& fog, double originY, double dirY, double distance) {
  if (!fog.directional) return 0.0;
  if (fog.convention != Convention::kEffectd) return engineInscatterWeight(fog, originY, dirY, distance);
  Fog beyond = fog;  // the same fog, over the ray's part where the glow starts
  beyond.startDistance = glowStart(fog);
  return 1.0 - factorAtElevation(beyond, originY, dirY, distance);
}

double lobe(const Directional& d, double cosTheta) {
  const double c = std::clamp(cosTheta, -1.0, 1.0);
  if (d.exponent) return c > 0.0 ? std::pow(c, *d.exponent) : 0.0;
  const double g = d.g;
  // 1 + g^2 - 2gc as a sum of two non-negative terms (no cancellation as |g| -> 1)
  const double den =
      g >= 0.0 ? (1.0 - g) * (1.0 - g) + 2.0 * g * (1.0 - c) : (1.0 + g) * (1.0 + g) - 2.0 * g * (1.0 + c);
  return (1.0 - g) * (1.0 + g) / (den * std::sqrt(den));
}

namespace {

// The sun's glow along the ray from eye to point (d long, unit y component dirY): none without
// a directional term.
glm::dvec3 glow(const Fog& fog, const glm::dvec3& eye, const glm::dvec3& point, double d, double dirY) {
  if (!fog.directional || !(d > 0.0)) return glm::dvec3(0.0);
  // Unreal's lobe looks from its clamped observer height
  const glm::dvec3 observer(eye.x, observerHeight(fog, eye.y), eye.z);
  const glm::dvec3 view = detail::rayBetween(observer, point).direction;
  const glm::dvec3 sun = fog.directional->direction / detail::length(fog.directional->direction);
  return inscatterWeight(fog, eye.y, dirY, d) * fog.directional->color * lobe(*fog.directional, glm::dot(view, sun));
}

}  // namespace

glm::dvec3 shade(const Fog& fog, const glm::dvec3& object, const glm::dvec3& eye, const glm::dvec3& point) {
  const detail::Ray ray = detail::rayBetween(eye, point);
  const double d = ray.length;
  const double dirY = std::clamp(ray.direction.y, -1.0, 1.0);
  return object * transmittance(fog, eye.y, dirY, d) + scattered(fog, eye.y, dirY, d) + glow(fog, eye, point, d, dirY);
}

double factor(const Fog& fog, const glm::dvec3& origin, const glm::dvec3& direction, double distance) {
  if (fog.type != FogType::kHeight) return factor(fog, distance);
  // The largest component scaled out first: directions of 1e-300 and 1e300 keep their angle.
  const double m = std::max({std::fabs(direction.x), std::fabs(direction.y), std::fabs(direction.z)});
  if (!(m > 0.0) || !finite(m)) return engineLimits(fog, distance, 1.0);
  const glm::dvec3 u = direction / m;
  const double dirY = std::clamp(u.y / detail::length(u), -1.0, 1.0);
  return factorAtElevation(fog, origin.y, dirY, distance);
}

namespace {

// Distance (from where the fog starts) at which the mode's own weight falls to `level`.
double modeDistanceTo(const Fog& fog, double level, double cameraHeight) {
  const bool byte = level <= 1.0 / 255.0;             // complete to 8 bits: where X3D and GL_LINEAR reach 0
  const double q = byte ? kLn255 : -std::log(level);  // e^-q = level
  switch (fog.type) {
    case FogType::kX3dLinear:
      if (!(fog.visibilityRange > 0.0)) return kInf;
      return byte ? fog.visibilityRange : fog.visibilityRange * (1.0 - level);
    case FogType::kX3dExponential:
      if (!(fog.visibilityRange > 0.0)) return kInf;
      return byte ? fog.visibilityRange : fog.visibilityRange * q / (1.0 + q);  // d / (V - d) = q
    case FogType::kGlLinear: return byte ? fog.end : fog.end - level * (fog.end - fog.start);
    case FogType::kGlExp: return fog.density > 0.0 ? q / fog.density : kInf;
    case FogType::kGlExp2: return fog.density > 0.0 ? std::sqrt(q) / fog.density : kInf;
    case FogType::kDistanceExp2: return fog.distanceCoefficient > 0.0 ? std::sqrt(q / fog.distanceCoefficient) : kInf;
    case FogType::kDistanceGaussian: {
      double l = byte ? std::log(255.0 * fog.peak) : std::log(fog.peak / level);
      if (l <= 0.0) return 0.0;
      return fog.distanceCoefficient > 0.0 ? std::sqrt(l / fog.distanceCoefficient) : kInf;
    }
    case FogType::kAtmospheric: {  // every varying channel done: the smallest positive coefficient
      double least = kInf;
      for (int c = 0; c < 3; ++c)
        for (double k : {fog.extinction[c], fog.inscattering[c]})
          if (k > 0.0) least = std::min(least, k);
      return least < kInf ? q / least : kInf;
    }
    case FogType::kHeight: {
      // Horizontal ray: tau = (sum of a e^{-b(y-h)}) t, so t = q / that sum, in log space.
      auto logDensity = [&](double a, double b, double h) {
        return a > 0.0 ? std::log(a) - b * (cameraHeight - h) : -kInf;
      };
      double l1 = logDensity(fog.density, fog.heightFalloff, fog.baseHeight), l = l1;
      if (const auto& s = fog.secondLayer) {
        double l2 = logDensity(s->density, s->heightFalloff, s->baseHeight), hi = std::max(l1, l2);
        l = hi == -kInf ? -kInf : hi + std::log1p(std::exp(std::min(l1, l2) - hi));
      }
      if (l == -kInf) return kInf;
      double logT = std::log(q) - l;
      return logT > 709.0 ? kInf : std::exp(logT);
    }
  }
  return kInf;
}

}  // namespace

double completeDistance(const Fog& fog, double cameraHeight) {
  const double level = std::max(1.0 / 255.0, 1.0 - fog.maxOpacity);
  const double mode = level >= 1.0 ? 0.0 : modeDistanceTo(fog, level, cameraHeight);
  double d = fog.startDistance + mode;
  if (fog.directional)  // the glow starts later, and is done as much later
    d = std::max(d, glowStart(fog) + mode);
  return std::min(d, fog.cutoffDistance);
}

std::optional<Error> validate(const Region& r) {
  if (r.shape == Region::Shape::kBox) {
    for (int i = 0; i < 3; ++i) {
      if (!finite(r.min[i]) || !finite(r.max[i])) return invalid("/box", "corners must be finite");
      if (r.min[i] > r.max[i]) return invalid("/box/max/" + std::to_string(i), "must be >= min");
    }
  } else {
    for (int i = 0; i < 3; ++i)
      if (!finite(r.center[i])) return invalid("/sphere/center/" + std::to_string(i), "must be finite");
    if (!finite(r.radius) || r.radius < 0.0) return invalid("/sphere/radius", "must be a finite number >= 0");
  }
  if (auto e = validate(r.fog)) return Error{e->kind, "/fog" + e->field, e->message};
  return std::nullopt;
}

double logVolume(const Region& r) {
  if (r.shape == Region::Shape::kBox) {  // halves: max - min may exceed the largest double
    const glm::dvec3 e = 0.5 * r.max - 0.5 * r.min;
    return std::log(e.x) + std::log(e.y) + std::log(e.z) + 3.0 * std::log(2.0);
  }
  return std::log(4.0 / 3.0 * 3.14159265358979323846) + 3.0 * std::log(r.radius);
}

int regionAt(const std::vector<Region>& regions, const glm::dvec3& p) {
  int best = -1;
  double bestVolume = kInf;
  for (size_t i = 0; i < regions.size(); ++i) {
    const Region& r = regions[i];
    bool inside;
    if (r.shape == Region::Shape::kBox) {
      inside = p.x >= r.min.x && p.x <= r.max.x && p.y >= r.min.y && p.y <= r.max.y && p.z >= r.min.z && p.z <= r.max.z;
    } else {
      inside = detail::rayBetween(r.center, p).length <= r.radius;
    }
    const double v = logVolume(r);
    if (inside && (best < 0 || v < bestVolume)) {
      best = static_cast<int>(i);
      bestVolume = v;
    }
  }
  return best;
}

Sample sampleAt(const Fog& global, const std::vector<Region>& regions, const glm::dvec3& camera,
                const glm::dvec3& point) {
  Sample s;
  s.region = regionAt(regions, point);
  const Fog& f = s.region < 0 ? global : regions[size_t(s.region)].fog;
  const detail::Ray ray = detail::rayBetween(camera, point);
  const double d = ray.length, dirY = std::clamp(ray.direction.y, -1.0, 1.0);
  // One evaluation of the weight; transmittance and colour follow from it (ATMOSPHERIC's per
  // channel), as shade() has them for a black object.
  s.factor = factorAtElevation(f, camera.y, dirY, d);
  const bool channels = f.type == FogType::kAtmospheric;
  s.transmittance = channels ? transmittance(f, camera.y, dirY, d) : glm::dvec3(s.factor);
  s.fogColor = (channels ? scattered(f, camera.y, dirY, d) : (1.0 - s.factor) * f.color) + glow(f, camera, point, d, dirY);
  return s;
}

}  // namespace effects::fog
