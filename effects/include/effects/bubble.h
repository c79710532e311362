// effects/bubble.h — soap bubble: seed 000's Snell's-law shader model, its mesh, shader
// variants, and physical thin-film colour.
//
// Source: seed 000 (soap bubble shader with Snell's law; eqns 3-11, constants of its results
// section), the Airy formula for a thin film, CIE 1931 colour matching. Digest:
// docs/effects.md section 3.
//
// Vectors: I = incident direction (camera -> surface, unit), N = unit outward normal,
// V = -I. gamma_out = N.V (eqn 4). Eqn 7 is printed with scalars; effectd implements the
// vector form it intends, which is the standard refraction vector
//   T = eta I + (eta gamma_out - gamma_in) N,  eta = n1 / n2,
// scaled by mu_bottom. When nu_in = eta nu_out >= 1 there is no refracted ray (total internal
// reflection): T = 0 and the final vector is the reflection alone.
// Time: phases are reduced modulo 2 pi in extended precision (reducedPhase), so t = 1e9 s
// gives the same result as the equivalent small t; shaders receive phases, not t.
// Thread-safety: pure functions, reentrant.
#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include "effects/common.h"
#include "effects/parallel.h"

#include "effects/export.h"

EFFECTS_API_BEGIN
namespace effects::bubble {

// Eqn 11 moves x by a sin(phase + k x): its Jacobian is diagonal, 1 + a k cos(...), and the
// surface folds where it reaches 0 (a k >= 1). The paper's literal wobble (a = 1, k = 1 per
// object unit) does: on the unit sphere at t = 7 it squashes the bubble into a sliver.
//   kRelative (default): a is a fraction of the radius and k radians per radius, so the shape
//     is the same at every size: x += R a (sin(phase + k x/R), cos(phase + k y/R), sin(...)).
//   kPaper: eqn 11's form in object units (x += a sin(phase + k x) ...), the paper's k = 1.
// Both keep a k <= kMaxWobbleStretch (the surface stretches by at most 1 +- a k); a request
// beyond it is refused (422 naming wobbleAmplitude), never clamped.
enum class WobbleVariant { kRelative, kPaper };
struct WobbleShape {
  double amplitude, frequency;
};
inline constexpr WobbleShape kRelativeWobble{0.03, 3.0};  // 3 % of the radius, 3 rad per radius
inline constexpr WobbleShape kPaperWobble{0.5, 1.0};      // the paper's k; its a = 1 folds, so 0.5
inline constexpr double kMaxWobbleStretch = 0.5;          // bound on a k
inline constexpr double kMaxWobbleFrequency = 64;         // rad per radius (or object unit)

struct Params {
  double n1 = 1.0;          // outside (air)
  double n2 = 1.33;         // film (water)
  double deltaSpeed = 2.0;  // wobble angular speed, rad/s (eqn 11)
  double betaSpeed = 0.4;   // texture-flow angular speed, rad/s (eqn 9)
  double rimPower = 2.8;    // eqn 10
  double muSpeed = 0.05;    // film drains: alpha = saturate(muSpeed t) (eqn 3), 1/s
  WobbleVariant wobbleVariant = WobbleVariant::kRelative;
  double wobbleAmplitude = kRelativeWobble.amplitude;  // of the variant's unit (see above)
  double wobbleFrequency = kRelativeWobble.frequency;
};
// Fields: "/n1", "/n2" in [1, 10]; speeds in [0, 1e6]; rimPower in [0, 1e3]; wobble amplitude
// >= 0 (relative: <= 1 radius), frequency in [0, kMaxWobbleFrequency], amplitude x frequency
// <= kMaxWobbleStretch.
[[nodiscard]] std::optional<Error> validate(const Params& p);
// The defaults of a wobble variant (what a request that names the variant alone gets).
WobbleShape wobbleDefaults(WobbleVariant v);

// Eqn 3: alpha = saturate(muSpeed t); top = lerp(1, 0.1, alpha), bottom = lerp(0.1, 1, alpha).
struct Film {
  double top = 1, bottom = 0.1;
};
Film film(const Params& p, double t);

// Eqns 4-5.
struct Interface {
  double gammaOut = 1, nuOut = 0, nuIn = 0, gammaIn = 1;
  bool totalInternalReflection = false;
};
Interface interface(const Params& p, double gammaOut);

glm::dvec3 reflection(const glm::dvec3& I, const glm::dvec3& N);                                  // eqn 6
glm::dvec3 refraction(const Params& p, const glm::dvec3& I, const glm::dvec3& N, double bottom);  // eqn 7
// Eqn 8: R mu_top + T. I and N need not be unit (they are normalised; zero -> +z / -z).
glm::dvec3 finalVector(const Params& p, const glm::dvec3& I, const glm::dvec3& N, double t);
double rim(const Params& p, double gammaOut);  // eqn 10, in [0, 1]

// omega t mod 2 pi in [0, 2 pi), computed in long double.
double reducedPhase(double omega, double t);
glm::dvec2 flowOffset(const Params& p, double t);  // eqn 9: (sin bt, cos bt)
// The wobble of a sphere of `radius` in object units: x += amplitude sin(phase + frequency x)
// (what the vertex shader's uWobbleAmplitude and uWobbleFrequency hold).
WobbleShape wobbleInObject(const Params& p, double radius);
glm::dvec3 wobble(const Params& p, const glm::dvec3& x, double t, double radius);  // eqn 11
// Whether a sphere of `radius` keeps its shape under the paper's wobble in float32 (radius >=
// 1e-3 x amplitude in object units; the relative wobble always does); kUnsatisfiable naming
// /radius otherwise.
std::optional<Error> wobbleFits(const Params& p, double radius);
glm::dvec3 moveTowards(const glm::dvec3& from, const glm::dvec3& to, double s);  // lerp, s clamped to [0, 1]

// ---- film thickness ---------------------------------------------------------------------------
// The film's thickness over the sphere (beyond seed 000; docs/effects.md section 3.3).
// Drainage: h = H(t) sqrt(s), s = (1 - y) / 2 the depth below the top in object space (y up):
// Mysels' profile of a vertical film draining under gravity, thin at the top, thick at the
// bottom; H(t) = lerp(bottomStartNm, bottomEndNm, alpha), alpha = saturate(muSpeed t) of eqn 3,
// the paper's drain as the first-order term. Swirl: a divergence-free flow on the sphere,
// v = x cross grad psi with psi a sum of seeded sines drifting at swirlSpeed; the film at a
// point is the drainage profile where it was `swirl` flow-seconds ago (traced back through the
// flow), so bands of thickness curl around without creating or losing film.
struct ThicknessOptions {
  uint64_t seed = 1;
  double bottomStartNm = 1000;   // bottom thickness of a young bubble (t = 0)
  double bottomEndNm = 300;      // ... once drained (alpha = 1)
  double swirl = 0.8;            // how far the flow carries the film, radians on the unit sphere
  double swirlSpeed = 0.25;      // how fast the flow pattern drifts, rad/s
  int width = 128, height = 64;  // texture: u = atan2(z, x) / 2 pi + 0.5 (REPEAT), v = 0 at y = -1
  bool measureError = true;      // the bilinear lookup against thicknessAt between texels
};
// Fields "/bottomStartNm", "/bottomEndNm" in [0, 1e5], "/swirl" in [0, 10],
// "/swirlSpeed" in [0, 1e6], "/width" in [4, 4096], "/height" in [2, 4096].
[[nodiscard]] std::optional<Error> validate(const ThicknessOptions& o);
// The exact thickness in nm at a point of the unit sphere (normalised; zero -> +y) at time t.
double thicknessAt(const Params& p, const ThicknessOptions& o, const glm::dvec3& unitPoint, double t);
// Without the field, the whole film takes the drainage profile's thickness at the equator.
double equatorThickness(const Params& p, const ThicknessOptions& o, double t);
struct ThicknessField {
  int width = 0, height = 0;
  std::vector<float> nm;                   // row-major, row 0 at v = 0 (the bottom), texel centres
  double meanErrorNm = 0, maxErrorNm = 0;  // bilinear lookup against thicknessAt between texels
  Stats stats;
};
Result<ThicknessField> thicknessField(const Params& p, const ThicknessOptions& o, double t,
                                      Parallel* parallel = nullptr);

// ---- mesh -----------------------------------------------------------------------------------
struct MeshOptions {
  int level = 3;  // icosphere subdivisions: 20 * 4^level triangles
  int maxLevel = 7;
  double radius = 1.0;
  double t = 0.0;  // time for the wobble
  bool wobble = true;
  std::optional<glm::dvec3> camera;  // when set: per-vertex final vectors and rim
  Parallel* parallel = nullptr;      // for the tangent frames; null = this thread only
};
struct Mesh {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec2> uvs;       // equirectangular; seam triangles run past u = 1 (REPEAT), own copies
  std::vector<glm::vec4> tangents;  // MikkTSpace
  std::vector<uint32_t> indices;
  std::vector<glm::vec3> finalVectors;  // when camera given
  std::vector<float> rim;
  Stats stats;
};
// What icosphere() checks before any work: p, then level (kLimitExceeded past maxLevel),
// radius in [1e-6, 1e6], wobbleFits when o.wobble, t finite.
[[nodiscard]] std::optional<Error> validate(const Params& p, const MeshOptions& o);
Result<Mesh> icosphere(const Params& p, const MeshOptions& o);

// ---- shaders ----------------------------------------------------------------------------------
// Two shading models (docs/effects.md sections 3.4-3.5):
//   kFilm (default): a soap film. Per fragment, the film's reflectance R (the thin-film table
//     at the fragment's thickness and |cos theta|: Airy, s and p, CIE) weights what the mirror
//     direction sees (the environment, plus each light's highlight); the light behind passes
//     through weighted 1 - R per channel (the film absorbs nothing). Two draws per face set:
//     uPass 0 writes (1 - R, 1 - opacity) blended with (ZERO, SRC_COLOR; ZERO, SRC_ALPHA), uPass 1
//     writes (R * seen, opacity) with (ONE, ONE), opacity the luminance of R; uPass 2 is one draw, premultiplied (R *
//     seen, luminance of R) with (ONE, ONE_MINUS_SRC_ALPHA), for engines that cannot draw twice (its transmission is
//     grey). Back faces see the film from inside (normal flipped by gl_FrontFacing): draw them first.
//   kPaper: seed 000's eqns 3-10 (final vector lookup, rim alpha, texture flow), straight alpha
//     blended with (SRC_ALPHA, ONE_MINUS_SRC_ALPHA); iridescence adds the table's colour.
enum class Shading { kFilm, kPaper };
// The paper model's colour and alpha without any feature (its uBaseColor).
inline const glm::dvec4 kBaseColor{1, 1, 1, 1};
inline constexpr int kMaxLights = 4;
struct Features {
  // The paper model's.
  bool reflection = true, refraction = true, rim = true, textureFlow = true, wobble = true, iridescence = false;
  // The film model's: thickness from the drainage/swirl texture (else one thickness for the
  // whole film), back faces, light highlights.
  bool thickness = true, backFace = true, highlight = true;
  Shading shading = Shading::kFilm;
};
enum class Glsl { kEs300, kCore330 };
struct ShaderSource {
  std::string vertex, fragment;
  std::vector<std::string> uniforms;    // every uniform the two stages declare
  std::vector<std::string> attributes;  // at locations 0, 1, ...
};
// A renderer may splice its own code into the fragment stage: `fragmentPrelude` goes after
// the declarations, `fragmentFinish` runs just before the write and may change `color` (vec4:
// straight alpha in the paper model; in the film model per uPass, with R the film's reflectance
// in scope); both see vWorld.
ShaderSource shader(const Features& f, Glsl version, const std::string& fragmentPrelude = "",
                    const std::string& fragmentFinish = "");
// What tells shader variants apart: the model and one bit per feature ("film:101101111"), for
// the caches of compiled or translated variants.
std::string variantKey(const Features& f);

// A directional light for the film's highlights: towards the light, its radiance, and the
// angular radius (degrees) at which its highlight falls to half.
struct Light {
  glm::dvec3 direction{0.5, 0.8, 0.6};
  glm::dvec3 color{1.0, 0.97, 0.92};
  double intensity = 6.0;
  double sizeDegrees = 1.5;
};
// The exponent n of the highlight lobe max(0, r . l)^n that halves at `sizeDegrees`.
double highlightSharpness(const Light& l);

// ---- thin film ----------------------------------------------------------------------------
// Reflectance of an air/film/air film (Airy), mean of s and p, at wavelength `nm`; the two
// polarisations apart (x: s, y: p). The film absorbs nothing: transmittance is 1 - R.
double filmReflectance(double ior, double thicknessNm, double cosTheta, double nm);
glm::dvec2 filmReflectanceSP(double ior, double thicknessNm, double cosTheta, double nm);
// Spectra to colour as the table does it: midpoints of `wavelengths` bins over 380-780 nm,
// weighted by D65 x CIE 1931, to linear sRGB, white-balanced (a spectrum of 1s gives (1, 1, 1)).
class SpectrumToRgb {
 public:
  explicit SpectrumToRgb(int wavelengths);
  const std::vector<double>& wavelengthsNm() const { return nm_; }
  glm::dvec3 operator()(const double* values) const;  // one value per wavelength
 private:
  std::vector<double> nm_;
  std::vector<glm::dvec3> weight_;
  glm::dvec3 white_;
};
// CIE76 Delta E*ab between two linear sRGB colours (D65, white = (1, 1, 1)).
double deltaE(const glm::dvec3& a, const glm::dvec3& b);
// Belcour & Barla 2017's analytic alternative: the Airy series to its second order, each order
// integrated against Gaussian fits of the CIE colour matching functions in closed form (their
// "evalSensitivity"), unpolarised Fresnel: linear sRGB without sampling wavelengths. Compared
// with the table in docs/error-vs-time.md (the thin-film section).
glm::dvec3 filmColorAnalytic(double ior, double thicknessNm, double cosTheta);
// Linear sRGB reflectance colour under D65 in `wavelengths` equal bands over 380-780 nm, each
// band's reflectance the mean of the Airy function over the band's phases (a film whose fringes
// are finer than a band gets their mean, the incoherent limit), white-balanced so that R = 1
// gives (1, 1, 1), then brought into the sRGB gamut (intoGamut). The thin-film table's method.
glm::dvec3 filmColor(double ior, double thicknessNm, double cosTheta, int wavelengths);
// The reference: the spectral integral over the CIE tables (linearly interpolated) by
// Gauss-Legendre quadrature with sub-intervals of at most `fringeFraction` of a fringe (of the
// sharpest fringe's peak at grazing incidence); converged to 1e-6 at the default.
glm::dvec3 filmColorReference(double ior, double thicknessNm, double cosTheta, double fringeFraction = 1.0 / 12);
// A linear sRGB colour with a negative channel (a saturated interference colour outside the
// sRGB gamut) moved towards the grey of its own luminance Y just far enough that every channel
// is >= 0: what a UNORM texture can hold, with hue and luminance kept. In-gamut colours are kept.
glm::dvec3 intoGamut(const glm::dvec3& linearSrgb);

struct ThinFilmOptions {
  double ior = 1.33;
  double thicknessMinNm = 0, thicknessMaxNm = 1000;
  int width = 256;           // thickness samples (u)
  int height = 256;          // cos(theta) samples (v), from 0 (row 0) to 1
  int wavelengths = 16;      // [3, 400]
  bool measureError = true;  // Delta E*ab against filmColorReference on a 32 x 32 sub-grid;
                             // false: on 4 x 4 texels (an estimate, 1/64 of the cost)
};
struct ThinFilmTable {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major, 3 per texel, linear sRGB
  double meanDeltaE = 0, maxDeltaE = 0;
  Stats stats;
};
Result<ThinFilmTable> thinFilmTable(const ThinFilmOptions& o);

}  // namespace effects::bubble
EFFECTS_API_END
