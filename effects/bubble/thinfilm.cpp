// Thin-film interference colour of a soap film (beyond seed 000; effects.md section 3).
//
// Airy reflectance of an air / film (index n, thickness d) / air film at incidence theta:
//   R = F sin^2(phi) / (1 + F sin^2(phi)),  F = 4 R12 / (1 - R12)^2,
//   phi = delta / 2 = 2 pi n d cos(theta_t) / lambda,
// R12 the Fresnel reflectance of the air/film interface, per polarisation; s and p averaged.
// Colour: XYZ = integral of R S xbar / integral of S ybar under D65 over 380-780 nm, the 5 nm
// CIE tables interpolated linearly; to linear sRGB (IEC 61966-2-1 matrix), divided by the colour
// of R = 1 (white-balanced), then brought into the sRGB gamut (intoGamut).
//
// The method (the table): `wavelengths` equal bins, each bin's D65 x CMF weight at its midpoint
// and its reflectance the mean of R over the bin's range of phase, in closed form:
//   mean R = 1 - (J(phi2) - J(phi1)) / (phi2 - phi1),  J(phi) = integral of 1/(1 + F sin^2),
// so that a film whose fringes are finer than a bin gets their mean (the incoherent limit,
// 2 R12 / (1 + R12), at 100 um) instead of an aliased sample.
// The reference (filmColorReference): the same integral by Gauss-Legendre quadrature on every
// 5 nm interval, subdivided until each sub-interval spans at most 1/12 of a fringe (narrower
// for sharp fringes at grazing incidence): nothing of the method's binning or averaging.
#include <algorithm>
#include <cmath>
#include <limits>

#include <glm/geometric.hpp>

#include "cie.h"
#include "effects/bubble.h"

namespace effects::bubble {
namespace {

constexpr double kPi = 3.14159265358979323846;

double table(const double* t, double nm) {
  double x = (nm - cie::kFirstNm) / cie::kStepNm;
  if (x <= 0) return t[0];
  if (x >= cie::kSamples - 1) return t[cie::kSamples - 1];
  int i = int(x);
  double f = x - i;
  return t[i] * (1 - f) + t[i + 1] * f;
}

glm::dvec3 xyzToLinearSrgb(const glm::dvec3& c) {
  return {3.2404542 * c.x - 1.5371385 * c.y - 0.4985314 * c.z, -0.9692660 * c.x + 1.8760108 * c.y + 0.0415560 * c.z,
          0.0556434 * c.x - 0.2040259 * c.y + 1.0572252 * c.z};
}
glm::dvec3 linearSrgbToXyz(const glm::dvec3& c) {
  return {0.4124564 * c.r + 0.3575761 * c.g + 0.1804375 * c.b, 0.2126729 * c.r + 0.7151522 * c.g + 0.0721750 * c.b,
          0.0193339 * c.r + 0.1191920 * c.g + 0.9503041 * c.b};
}

// CIE L*a*b* of a linear sRGB colour, D65 white = sRGB (1, 1, 1).
glm::dvec3 lab(const glm::dvec3& rgb) {
  const glm::dvec3 white = linearSrgbToXyz({1, 1, 1});
  glm::dvec3 xyz = linearSrgbToXyz(rgb) / white;
  auto f = [](double t) { return t > 216.0 / 24389 ? std::cbrt(t) : (24389.0 / 27 * t + 16) / 116; };
  double fx = f(xyz.x), fy = f(xyz.y), fz = f(xyz.z);
  return {116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz)};
}

// Spectral sampling: midpoints of `n` equal bins over 380-780 nm, with D65 x CMF weights.
struct Sampling {
  std::vector<double> nm;
  std::vector<glm::dvec3> weight;  // S * (xbar, ybar, zbar) * dlambda / sum S ybar dlambda
  glm::dvec3 white;                // linear sRGB of R = 1
};

Sampling sampling(int n) {
  Sampling s;
  const double step = 400.0 / n;
  double norm = 0;
  for (int k = 0; k < n; ++k) {
    double nm = 380.0 + (k + 0.5) * step, S = table(cie::kD65, nm);
    s.nm.push_back(nm);
    s.weight.push_back(S * glm::dvec3(table(cie::kXBar, nm), table(cie::kYBar, nm), table(cie::kZBar, nm)));
    norm += S * table(cie::kYBar, nm);
  }
  glm::dvec3 sum(0);
  for (auto& w : s.weight) sum += (w /= norm);
  s.white = xyzToLinearSrgb(sum);
  return s;
}

// The film's two interfaces at incidence cos(theta) = cosTheta: the Airy coefficient F per
// polarisation (s, p) and the film's cos(theta_t). F is infinite at grazing incidence.
struct Interfaces {
  glm::dvec2 F{0.0};
  double cosT = 1.0;
};
Interfaces interfaces(double n, double cosTheta) {
  const double c1 = std::clamp(std::abs(cosTheta), 0.0, 1.0);
  const double sin1 = std::sqrt(std::max(0.0, 1 - c1 * c1));
  const double sinT = sin1 / n;  // n >= 1: never total internal reflection entering the film
  Interfaces f;
  f.cosT = std::sqrt(std::max(0.0, 1 - sinT * sinT));
  const double rs = (c1 - n * f.cosT) / (c1 + n * f.cosT), rp = (n * c1 - f.cosT) / (n * c1 + f.cosT);
  for (int k = 0; k < 2; ++k) {
    const double R12 = k == 0 ? rs * rs : rp * rp;
    f.F[k] = R12 >= 1 ? std::numeric_limits<double>::infinity() : 4 * R12 / ((1 - R12) * (1 - R12));
  }
  return f;
}

double airy(double F, double phi) {
  if (std::isinf(F)) return 1.0;  // grazing incidence: the interface reflects everything
  const double s = std::sin(phi), s2 = s * s;
  return F * s2 / (1 + F * s2);
}

// J(phi) = integral from 0 to phi of 1 / (1 + F sin^2 x) dx, continuous across the branches of
// tan: (m pi + atan(a tan(phi - m pi))) / a, a = sqrt(1 + F), m = round(phi / pi); for s and p
// at once (a per polarisation), as they share phi and so the tangent.
glm::dvec2 airyPrimitive(const glm::dvec2& a, double phi) {
  const double m = std::nearbyint(phi / kPi), t = std::tan(phi - m * kPi);
  return {(m * kPi + std::atan(a.x * t)) / a.x, (m * kPi + std::atan(a.y * t)) / a.y};
}

// The method: each band's reflectance the mean of R over its phases (see the top of the file),
// per polarisation. The bands share their edges, so J is taken once an edge: 1 - (J2 - J1) / (phi2
// - phi1), or Simpson's rule where the phase width is below 1e-3 (the difference would cancel).
glm::dvec3 color(const Sampling& s, double ior, double d, double cosTheta) {
  if (!(ior > 1)) return glm::dvec3(0);
  const Interfaces f = interfaces(ior, cosTheta);
  if (std::isinf(f.F.x) && std::isinf(f.F.y)) return intoGamut(glm::dvec3(1));  // grazing: R = 1
  const size_t n = s.nm.size();
  const double C = 2 * kPi * ior * std::max(0.0, d) * f.cosT, width = 400.0 / double(n);
  // Band k spans [380 + k width, 380 + (k + 1) width] nm: phases from C / its top to C / its bottom.
  auto edge = [&](size_t k) { return C / (380.0 + width * double(k)); };
  const glm::dvec2 a = glm::sqrt(1.0 + f.F);  // infinite at grazing: that polarisation is R = 1 below
  auto primitive = [&](double phi) { return airyPrimitive(a, phi); };
  double phiHi = edge(0);
  glm::dvec2 J = primitive(phiHi);
  glm::dvec3 xyz(0);
  for (size_t k = 0; k < n; ++k) {
    const double phiLo = edge(k + 1), span = phiHi - phiLo;
    const glm::dvec2 Jnext = primitive(phiLo);
    double R = 0;
    for (int p = 0; p < 2; ++p) {
      const double F = f.F[p];
      if (std::isinf(F))
        R += 0.5;  // this polarisation reflects everything
      else if (span < 1e-3)
        R += (airy(F, phiLo) + 4 * airy(F, 0.5 * (phiLo + phiHi)) + airy(F, phiHi)) / 12;
      else
        R += std::clamp(1 - (J[p] - Jnext[p]) / span, 0.0, 1.0) / 2;
    }
    xyz += R * s.weight[k];
    J = Jnext;
    phiHi = phiLo;
  }
  return intoGamut(xyzToLinearSrgb(xyz) / s.white);
}

}  // namespace

glm::dvec3 intoGamut(const glm::dvec3& rgb) {
  const double least = std::min({rgb.r, rgb.g, rgb.b});
  if (least >= 0) return rgb;
  const glm::dvec3 luminance(0.2126729, 0.7151522, 0.0721750);  // Y of linear sRGB (the matrix's row)
  const double grey = std::max(0.0, glm::dot(luminance, rgb)) / (luminance.r + luminance.g + luminance.b);
  // rgb + t (grey - rgb): the grey of the same luminance at t = 1, every channel >= 0 from t on.
  const double t = -least / (grey - least);
  return glm::max(rgb + t * (glm::dvec3(grey) - rgb), glm::dvec3(0));
}

glm::dvec2 filmReflectanceSP(double n, double d, double cosTheta, double nm) {
  if (!(n > 1)) return {0, 0};  // a film of air's index has no interfaces (and 0/0 at grazing incidence)
  const Interfaces f = interfaces(n, cosTheta);
  const double phi = 2 * kPi * n * std::max(0.0, d) * f.cosT / nm;  // delta / 2
  return {airy(f.F.x, phi), airy(f.F.y, phi)};
}

glm::dvec3 filmColorReference(double n, double d, double cosTheta, double fringeFraction) {
  // 5-point Gauss-Legendre on [-1, 1]
  static const double kX[5] = {-0.9061798459386640, -0.5384693101056831, 0.0, 0.5384693101056831, 0.9061798459386640};
  static const double kW[5] = {0.2369268850561891, 0.4786286704993665, 0.5688888888888889, 0.4786286704993665,
                               0.2369268850561891};
  const bool film = n > 1;
  const Interfaces f = interfaces(std::max(n, 1.0), cosTheta);
  const double C = 2 * kPi * std::max(n, 1.0) * std::max(0.0, d) * f.cosT;
  // A fringe of R spans pi of phase; its peaks are about pi / sqrt(1 + F) wide.
  // (No film, or F infinite at grazing incidence: R is constant and needs no subdivision.)
  const double Fmax = std::max(f.F.x, f.F.y);
  const double sharpest = film && std::isfinite(Fmax) ? std::min(std::sqrt(1 + Fmax), 1e3) : 1.0;
  const double maxStep = fringeFraction * kPi / sharpest;
  glm::dvec3 xyz(0), white(0);
  for (int i = 0; i + 1 < cie::kSamples; ++i) {
    const double lo = cie::kFirstNm + i * cie::kStepNm, hi = lo + cie::kStepNm;
    const int parts = std::max(1, int(std::ceil((C / lo - C / hi) / maxStep)));
    const double h = cie::kStepNm / parts;
    for (int k = 0; k < parts; ++k)
      for (int q = 0; q < 5; ++q) {
        const double nm = lo + h * (k + 0.5 + 0.5 * kX[q]), u = (nm - lo) / cie::kStepNm;
        auto lerp = [&](const double* t) { return t[i] * (1 - u) + t[i + 1] * u; };
        const glm::dvec3 w =
            0.5 * h * kW[q] * lerp(cie::kD65) * glm::dvec3(lerp(cie::kXBar), lerp(cie::kYBar), lerp(cie::kZBar));
        const double phi = C / nm;
        const double R = film ? 0.5 * (airy(f.F.x, phi) + airy(f.F.y, phi)) : 0.0;
        xyz += R * w;
        white += w;
      }
  }
  return intoGamut(xyzToLinearSrgb(xyz / white.y) / xyzToLinearSrgb(white / white.y));
}

double filmReflectance(double n, double d, double cosTheta, double nm) {
  const glm::dvec2 r = filmReflectanceSP(n, d, cosTheta, nm);
  return (r.x + r.y) / 2;
}

SpectrumToRgb::SpectrumToRgb(int wavelengths) {
  const Sampling s = sampling(std::clamp(wavelengths, 1, 400));
  nm_ = s.nm;
  weight_ = s.weight;
  white_ = s.white;
}

glm::dvec3 SpectrumToRgb::operator()(const double* values) const {
  glm::dvec3 xyz(0);
  for (size_t k = 0; k < nm_.size(); ++k) xyz += values[k] * weight_[k];
  return xyzToLinearSrgb(xyz) / white_;
}

double deltaE(const glm::dvec3& a, const glm::dvec3& b) { return glm::length(lab(a) - lab(b)); }

namespace {

// Unpolarised Fresnel reflectance entering a medium of relative index eta at cos(theta) = c.
double fresnel(double c, double eta) {
  const double g2 = eta * eta - 1 + c * c;
  if (g2 <= 0) return 1;  // total internal reflection
  const double g = std::sqrt(g2), a = (g - c) / (g + c), b = (c * (g + c) - 1) / (c * (g - c) + 1);
  return 0.5 * a * a * (1 + b * b);
}

// The CIE functions' response to cos(2 pi opd / lambda + shift), from Gaussian fits of x, y, z
// (Belcour & Barla 2017, supplemental), as linear sRGB.
glm::dvec3 sensitivity(double opdNm, double shift) {
  const double phase = 2 * kPi * opdNm * 1e-9;
  const glm::dvec3 value(5.4856e-13, 4.4201e-13, 5.2481e-13), mean(1.6810e+06, 1.7953e+06, 2.2084e+06),
      variance(4.3278e+09, 9.3046e+09, 6.6121e+09);
  glm::dvec3 xyz;
  for (int i = 0; i < 3; ++i)
    xyz[i] = value[i] * std::sqrt(2 * kPi * variance[i]) * std::cos(mean[i] * phase + shift) *
             std::exp(-phase * phase * variance[i]);
  xyz.x += 9.7470e-14 * std::sqrt(2 * kPi * 4.5282e+09) * std::cos(2.2399e+06 * phase + shift) *
           std::exp(-4.5282e+09 * phase * phase);
  return xyzToLinearSrgb(xyz / 1.0685e-7);
}

}  // namespace

glm::dvec3 filmColorAnalytic(double n, double d, double cosTheta) {
  if (!(n > 1)) return glm::dvec3(0);
  const double c1 = std::clamp(std::abs(cosTheta), 0.0, 1.0);
  const double sin2 = (1 - c1 * c1) / (n * n), c2 = std::sqrt(std::max(0.0, 1 - sin2));
  const double R12 = fresnel(c1, n), T121 = 1 - R12, R23 = fresnel(c2, 1 / n);
  if (R12 >= 1) return glm::dvec3(1);
  // Air / film / air: the round trip's two reflections shift the phase by pi + pi.
  const double opd = 2 * n * std::max(0.0, d) * c2, r123 = std::sqrt(R12 * R23);
  const double Rs = T121 * T121 * R23 / (1 - R12 * R23);
  glm::dvec3 I(R12 + Rs);
  double C = Rs - T121;
  const glm::dvec3 white = sensitivity(0, 0);  // the fits' flat spectrum: balanced to (1, 1, 1) as the table is
  for (int m = 1; m <= 2; ++m) {
    C *= r123;
    I += C * 2.0 * sensitivity(m * opd, 0.0) / white;
  }
  return glm::max(I, glm::dvec3(0));
}

glm::dvec3 filmColor(double ior, double thicknessNm, double cosTheta, int wavelengths) {
  return color(sampling(std::clamp(wavelengths, 1, 400)), ior, thicknessNm, cosTheta);
}

Result<ThinFilmTable> thinFilmTable(const ThinFilmOptions& o) {
  if (!(o.ior >= 1 && o.ior <= 3)) return invalid("/ior", "must be in [1, 3]");
  if (!(o.thicknessMinNm >= 0 && o.thicknessMaxNm > o.thicknessMinNm && o.thicknessMaxNm <= 1e5))
    return invalid("/thicknessRange", "must satisfy 0 <= min < max <= 100000 nm");
  if (o.width < 2 || o.height < 2 || size_t(o.width) * size_t(o.height) > 1u << 20)
    return overLimit("/size", "width and height >= 2, width * height <= 1048576");
  if (o.wavelengths < 3 || o.wavelengths > 400) return invalid("/wavelengths", "must be in [3, 400]");
  Stopwatch watch;
  ThinFilmTable out;
  out.width = o.width;
  out.height = o.height;
  out.rgb.resize(size_t(o.width) * size_t(o.height) * 3);
  const Sampling s = sampling(o.wavelengths);
  auto thickness = [&](int x) { return o.thicknessMinNm + (o.thicknessMaxNm - o.thicknessMinNm) * x / (o.width - 1); };
  auto cosine = [&](int y) { return double(y) / (o.height - 1); };
  for (int y = 0; y < o.height; ++y)
    for (int x = 0; x < o.width; ++x) {
      glm::dvec3 c = color(s, o.ior, thickness(x), cosine(y));
      for (int k = 0; k < 3; ++k) out.rgb[(size_t(y) * o.width + x) * 3 + k] = float(c[k]);
    }
  out.stats.method = "airy-" + std::to_string(o.wavelengths) + "-bands";
  out.stats.elapsedMs = watch.ms();
  // Delta E against the reference on a 32 x 32 sub-grid (measured), or on 4 x 4 texels (an
  // estimate at 1/64 of the cost: measureError false).
  Stopwatch errorWatch;
  const int grid = o.measureError ? 32 : 4;
  double sum = 0;
  size_t n = 0;
  for (int y = 0; y < o.height; y += std::max(1, o.height / grid))
    for (int x = 0; x < o.width; x += std::max(1, o.width / grid)) {
      const float* c = &out.rgb[(size_t(y) * o.width + x) * 3];
      double de = glm::length(lab({c[0], c[1], c[2]}) - lab(filmColorReference(o.ior, thickness(x), cosine(y))));
      sum += de;
      out.maxDeltaE = std::max(out.maxDeltaE, de);
      ++n;
    }
  out.meanDeltaE = sum / double(n);
  out.stats.error = out.meanDeltaE;
  out.stats.errorKind = o.measureError ? "measured" : "estimate";
  out.stats.errorMetric =
      "mean CIE76 Delta E*ab over a " + std::to_string(grid) + " x " + std::to_string(grid) + " sub-grid";
  out.stats.reference =
      "the spectral integral by Gauss-Legendre quadrature, 5 nodes per sub-interval, at least 12 per fringe";
  out.stats.counters["maxDeltaE"] = out.maxDeltaE;
  out.stats.errorMs = errorWatch.ms();
  out.stats.counters["wavelengths"] = o.wavelengths;
  return out;
}

}  // namespace effects::bubble
