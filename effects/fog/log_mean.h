// Small numerics the fog's closed forms share (fog.cpp, conventions.cpp; private to the library):
// every product, square and length here is safe across the whole range of double.
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/vec3.hpp>

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

// |v| without overflow or underflow in the squares: the largest component scaled out first, so
// that lengths of 1e200 and 1e-300 come out as themselves (glm::length gives inf and 0).
inline double length(const glm::dvec3& v) {
  const double m = std::max({std::fabs(v.x), std::fabs(v.y), std::fabs(v.z)});
  if (!(m > 0.0) || std::isinf(m)) return m;  // 0, infinity (or NaN)
  const glm::dvec3 u = v / m;
  return m * std::sqrt(u.x * u.x + u.y * u.y + u.z * u.z);
}

// The ray from `from` to `to`: its length (infinity where it exceeds the largest double) and
// its unit direction, both computed from half the difference so that no step overflows.
struct Ray {
  double length = 0.0;
  glm::dvec3 direction{0.0};  // zero when length is 0
};
inline Ray rayBetween(const glm::dvec3& from, const glm::dvec3& to) {
  const glm::dvec3 half = 0.5 * to - 0.5 * from;
  const double h = length(half);
  if (!(h > 0.0)) return {};
  return {2.0 * h, half / h};
}

// exp(-c * d^2) for c, d >= 0 where d^2 may overflow or fall below the normal doubles (the
// product is then taken in log space); 0 * infinity counts as 0 as in mulZero.
inline double expMinusCD2(double c, double d) {
  if (c == 0.0 || d == 0.0) return 1.0;
  const double d2 = d * d;
  if (std::isfinite(d2) && d2 >= std::numeric_limits<double>::min()) return std::exp(-c * d2);
  const double l = std::log(c) + 2.0 * std::log(d);  // ln(c d^2)
  return l > 709.0 ? 0.0 : std::exp(-std::exp(l));
}

}  // namespace effects::fog::detail
