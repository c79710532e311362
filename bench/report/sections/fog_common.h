// The fog sections' one set of parameters for every fog type (each type reads the ones it uses).
#pragma once

#include <effects/fog.h>

#include "../report.h"

namespace report {

namespace fg = effects::fog;

inline fg::Fog reportFog(fg::FogType t) {
  fg::Fog f;
  f.type = t;
  f.visibilityRange = 100;
  f.start = 10, f.end = 100;
  f.density = 0.03;
  f.distanceCoefficient = 0.0005;
  f.heightFalloff = 0.2;
  f.extinction = {0.01, 0.02, 0.04};
  f.inscattering = {0.005, 0.015, 0.03};
  return f;
}

// The limit of use shared by the fog sections.
inline Metric fogMetric(std::string id, std::string name) {
  return {std::move(id), "err", std::move(name), 0.02, "a fog weight 0.02 off is 5 steps of 8-bit colour"};
}

}  // namespace report
