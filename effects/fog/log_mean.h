// Small numerics the fog's closed forms share (fog.cpp, conventions.cpp; private to the library).
#pragma once

#include <cmath>

namespace effects::fog::detail {

// x * y where 0 * infinity counts as 0: a zero coefficient means "no fog", whatever the distance
// (and a level ray to the sky rises by 0).
inline double mulZero(double x, double y) { return (x == 0.0 || y == 0.0) ? 0.0 : x * y; }

// log g(x), g(x) = (1 - e^-x) / x: the mean of e^(-x s) over s in [0, 1], stable for all real x.
inline double logG(double x) {
  if (x == 0.0) return 0.0;
  if (x > 0.0) return std::log(-std::expm1(-x)) - std::log(x);
  if (x > -700.0) return std::log(std::expm1(-x)) - std::log(-x);
  return -x - std::log(-x);  // e^-x dominates; log1p(-e^x) underflows to 0
}

}  // namespace effects::fog::detail
