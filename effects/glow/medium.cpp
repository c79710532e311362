// The medium a glow is seen through, from a scene's own fog (glow.h).
#include <algorithm>
#include <cmath>

#include "effects/glow.h"

namespace effects::glow {

double thicknessAlong(const fog::Fog& global, const std::vector<fog::Region>& regions, const glm::dvec3& eye,
                      const glm::dvec3& point) {
  const fog::Sample s = fog::sampleAt(global, regions, eye, point);
  const double mean = (s.transmittance.r + s.transmittance.g + s.transmittance.b) / 3;
  // e^-745 is the smallest double: a transmittance of 0 is that thick, not infinitely.
  return mean > 0 ? std::min(-std::log(std::min(mean, 1.0)), 745.0) : 745.0;
}

double forwardScatteringOf(const fog::Fog& fog) {
  if (!fog.directional) return kDefaultForwardScattering;
  const fog::Directional& d = *fog.directional;
  // Unreal's lobe max(cos, 0)^n has mean cosine (n + 1)/(n + 2) on the forward hemisphere (fog.h).
  const double g = d.exponent ? (*d.exponent + 1) / (*d.exponent + 2) : d.g;
  return std::clamp(g, 0.0, 1.0);
}

}  // namespace effects::glow
