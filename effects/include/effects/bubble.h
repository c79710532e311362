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

namespace effects::bubble {

struct Params {
  double n1 = 1.0;               // outside (air)
  double n2 = 1.33;              // film (water)
  double deltaSpeed = 2.0;       // wobble angular speed, rad/s (eqn 11)
  double betaSpeed = 0.4;        // texture-flow angular speed, rad/s (eqn 9)
  double rimPower = 2.8;         // eqn 10
  double muSpeed = 0.05;         // film drains: alpha = saturate(muSpeed t) (eqn 3), 1/s
  double wobbleAmplitude = 1.0;  // eqn 11's sin() term is scaled by this (paper: 1); <= 1, as
                                 // a larger one folds the surface
};
// Fields: "/n1", "/n2" in [1, 10]; speeds in [0, 1e6]; rimPower in [0, 1e3]; amplitude [0, 1e6].
std::optional<Error> validate(const Params& p);

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
glm::dvec2 flowOffset(const Params& p, double t);                                // eqn 9: (sin bt, cos bt)
glm::dvec3 wobble(const Params& p, const glm::dvec3& x, double t);               // eqn 11
// Whether a sphere of `radius` keeps its shape under the wobble in float32 (radius >= 1e-3 x
// wobbleAmplitude); kUnsatisfiable naming /radius otherwise.
std::optional<Error> wobbleFits(const Params& p, double radius);
glm::dvec3 moveTowards(const glm::dvec3& from, const glm::dvec3& to, double s);  // lerp, s clamped to [0, 1]

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
Result<Mesh> icosphere(const Params& p, const MeshOptions& o);

// ---- shaders ----------------------------------------------------------------------------------
struct Features {
  bool reflection = true, refraction = true, rim = true, textureFlow = true, wobble = true, iridescence = false;
};
enum class Glsl { kEs300, kCore330 };
struct ShaderSource {
  std::string vertex, fragment;
  std::vector<std::string> uniforms;  // every uniform the two stages declare
};
// A renderer may splice its own code into the fragment stage: `fragmentPrelude` goes after
// the declarations, `fragmentFinish` runs just before the write and may change `color`
// (vec4, straight alpha); both see vWorld (world position).
ShaderSource shader(const Features& f, Glsl version, const std::string& fragmentPrelude = "",
                    const std::string& fragmentFinish = "");

// ---- thin film ----------------------------------------------------------------------------
// Reflectance of an air/film/air film (Airy), mean of s and p, at wavelength `nm`.
double filmReflectance(double ior, double thicknessNm, double cosTheta, double nm);
// Linear sRGB reflectance colour under D65 using `wavelengths` midpoint samples over
// 380-780 nm (white-balanced so that R = 1 gives (1, 1, 1)); 400 = the 1 nm reference.
glm::dvec3 filmColor(double ior, double thicknessNm, double cosTheta, int wavelengths);

struct ThinFilmOptions {
  double ior = 1.33;
  double thicknessMinNm = 0, thicknessMaxNm = 1000;
  int width = 256;           // thickness samples (u)
  int height = 256;          // cos(theta) samples (v), from 0 (row 0) to 1
  int wavelengths = 16;      // [3, 400]
  bool measureError = true;  // Delta E*ab against the 1 nm reference on a sub-grid
};
struct ThinFilmTable {
  int width = 0, height = 0;
  std::vector<float> rgb;  // row-major, 3 per texel, linear sRGB
  double meanDeltaE = 0, maxDeltaE = 0;
  Stats stats;
};
Result<ThinFilmTable> thinFilmTable(const ThinFilmOptions& o);

}  // namespace effects::bubble
