// effects/fog.h — fog weight functions, local fog regions, exact height fog, colour tables.
//
// Source: seed 003 (Park, Chin & Kim, "Improving VRML/X3D Fog Effect Using Distance
// Coefficient"), ISO/IEC 19775-1 (X3D Fog/LocalFog), OpenGL 1.x fixed-function fog, and the
// exponential height fog engines ship (Unreal, Filament).
//
// Every mode yields the *object weight* f in [0, 1] (X3D's name; the paper's density rho):
// the final colour is C = f * C_object + (1 - f) * C_fog (X3D; seed 003 eqn 3). f is
// non-increasing in distance and finite for every finite or infinite non-negative distance.
//
// Units: distances in scene units (metres by convention); colours linear RGB in [0, 1].
// Thread-safety: all functions are pure and reentrant.
#pragma once

#include <cstddef>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include <glm/vec3.hpp>

#include "effects/common.h"

#include "effects/export.h"

EFFECTS_API_BEGIN
namespace effects::fog {

enum class FogType {
  kX3dLinear,         // X3D "LINEAR":      f = (V - d) / V for d < V, else 0; V = 0 disables fog
  kX3dExponential,    // X3D "EXPONENTIAL": f = exp(-d / (V - d)) for d < V, else 0
  kGlLinear,          // GL_LINEAR:         f = clamp((end - d) / (end - start), 0, 1)
  kGlExp,             // GL_EXP:            f = exp(-density * d)
  kGlExp2,            // GL_EXP2:           f = exp(-(density * d)^2)
  kDistanceExp2,      // seed 003 eqn 1:    f = 1 / e^(d_c * z^2)  (GL_EXP2 with density sqrt(d_c))
  kDistanceGaussian,  // seed 003 eqn 2:    f = peak * e^(-d_c * z^2)   (see below)
  kHeight,            // exponential height fog: f = exp(-tau), tau the exact optical depth
  kAtmospheric,       // Bevy FogFalloff::Atmospheric: per channel, C = object * exp(-extinction d)
                      //   + color * (1 - exp(-inscattering d)); f = the channels' mean transmittance
                      //   (under the engine terms as a whole: max(mean, 1 - maxOpacity))
};

// Seed 003 eqn 2 prints rho = (1/sqrt(2*pi)) * e^(-0.5 z^2) with no d_c although the text says
// it depends on d_c. effectd parameterises it as rho = peak * e^(-d_c * z^2): the printed curve
// is d_c = 0.5 with the default peak = 1/sqrt(2*pi). peak < 1 means objects never show their
// full colour (the paper's curve starts at 0.399); peak = 1 makes it identical to eqn 1.
inline constexpr double kPaperGaussianPeak = 0.3989422804014327;  // 1/sqrt(2*pi)

// Height fog's second layer (Unreal's Second Fog Data): density a2 * e^(-b2 (y - h2)), its
// optical depth added to the first layer's, exactly.
struct HeightLayer {
  double density = 0.0;        // a2 >= 0 at baseHeight
  double heightFalloff = 0.1;  // b2 >= 0
  double baseHeight = 0.0;     // h2
};

// Directional in-scattering: light from a sun scattered towards the viewer (Unreal's
// DirectionalInscattering*, the glow of fog towards a low sun). Over the part of the ray
// beyond startDistance the fog scatters `color` with a phase lobe of the angle theta between
// the view ray and `direction`:  C += (1 - f_dir) * color * lobe(cos theta), f_dir the fog's
// weight over that part (fog.h's rules: start, maxOpacity, cutoff). Because the lobe is the
// same all along a ray, the colour is separable: tables hold 1 - f_dir beside f, and the
// lobe is a closed form per pixel.
//   lobe = 4 pi p_HG(cos theta; g) = (1 - g^2) / (1 + g^2 - 2 g cos theta)^1.5  (Henyey-Greenstein,
//          scaled so that g = 0 gives 1, the fog colour's scale; it averages 1 over the sphere)
//   or Unreal's max(cos theta, 0)^exponent when `exponent` is given (a lobe of mean cosine
//   (n+1)/(n+2) on the forward hemisphere: the HG g of the same mean cosine).
struct Directional {
  glm::dvec3 color{1.0, 0.8, 0.6};       // linear RGB, each in [0, 1e6] (HDR allowed)
  glm::dvec3 direction{0.0, 0.0, -1.0};  // towards the light; non-zero, need not be unit
  double g = 0.7;                        // Henyey-Greenstein asymmetry in (-1, 1)
  std::optional<double> exponent;        // (0, 1e6]: Unreal's form instead of HG
  double startDistance = 0.0;            // >= 0; the glow starts at max(this, fog startDistance)
};

// Whose formulas a HEIGHT fog follows, with the same parameters (docs/effects.md §2.4):
//   kEffectd   the exact optical depth over [startDistance, d], the glow from max(startDistance,
//              directional.startDistance) capped like the fog;
//   kFilament  Filament's surface fog: the mean density over [0, d] times (d - startDistance),
//              near-level rays at the camera's density, the glow from directional.startDistance,
//              not capped; one layer; the glow's lobe max(cos, 0)^exponent;
//   kUnreal    Unreal's ExponentialHeightFog in its base-2 form (density a / ln2^2, falloff b / ln2
//              per unit), its near-level Taylor term, exponent clamps and observer height clamp
//              (65536 units above the lowest layer), the glow from startDistance +
//              directional.startDistance, not capped; the lobe max(cos, 0)^exponent.
enum class Convention { kEffectd, kFilament, kUnreal };

struct Fog {
  FogType type = FogType::kX3dLinear;
  Convention convention = Convention::kEffectd;  // kHeight only
  glm::dvec3 color{1.0, 1.0, 1.0};               // X3D default 1 1 1; each component in [0, 1]
  double visibilityRange = 0.0;                  // X3D V >= 0; 0 = no fog
  double start = 0.0, end = 1.0;                 // GL_LINEAR, 0 <= start < end
  double density = 1.0;                          // GL_EXP/GL_EXP2 >= 0; height fog: density a >= 0 at baseHeight
  double distanceCoefficient = 0.07;             // d_c >= 0 (seed 003's worked example uses 0.07)
  double peak = kPaperGaussianPeak;              // kDistanceGaussian only, in (0, 1]
  double heightFalloff = 0.1;                    // height fog b >= 0: density a * e^(-b (y - h))
  double baseHeight = 0.0;                       // height fog h
  glm::dvec3 extinction{0.0};                    // kAtmospheric: per channel, per unit distance, each >= 0
  glm::dvec3 inscattering{0.0};                  // kAtmospheric: per channel, per unit distance, each >= 0
  // What engines add on top of every mode (Unreal ExponentialHeightFog, Filament FogOptions;
  // docs/effects.md), applied in this order:
  double startDistance = 0.0;  // >= 0: the first part of every ray is clear (Unreal StartDistance,
                               // Filament distance): distance modes see max(0, d - start), height
                               // fog integrates from start to d
  double maxOpacity = 1.0;     // in [0, 1]: fog never hides more than this, f >= 1 - maxOpacity
                               // (Unreal FogMaxOpacity, Filament maximumOpacity)
  double cutoffDistance =
      std::numeric_limits<double>::infinity();  // > 0: beyond it f = 1, unfogged
                                                // (Unreal FogCutoffDistance, Filament cutOffDistance: the skybox)
  std::optional<HeightLayer> secondLayer;       // kHeight only
  std::optional<Directional> directional;       // every mode
};

// Names used on the wire ("LINEAR", "EXPONENTIAL", "GL_LINEAR", ... "HEIGHT"; "effectd", ...).
const char* toString(FogType type);
std::optional<FogType> fogTypeFromString(const std::string& name);
const char* toString(Convention convention);
std::optional<Convention> conventionFromString(const std::string& name);

// The weight f and the glow's weight 1 - f_dir of a HEIGHT fog in an engine's convention
// (kFilament, kUnreal; conventions.cpp), for a ray from height originY with unit direction
// y component dirY: what factorAtElevation and inscatterWeight return for them.
double engineFactor(const Fog& fog, double originY, double dirY, double distance);
double engineInscatterWeight(const Fog& fog, double originY, double dirY, double distance);
// Where the glow starts along a ray in the fog's convention.
double glowStart(const Fog& fog);
// The height the fog is seen from: the eye's, but Unreal's at most 65536 units above its lowest
// layer with density (its rays, and its glow's lobe, start there).
double observerHeight(const Fog& fog, double eyeY);

// Field errors name the Fog member, e.g. "/visibilityRange".
[[nodiscard]] std::optional<Error> validate(const Fog& fog);

// f for a point at `distance` from the viewer. For kHeight this is a horizontal ray at
// baseHeight (use factorAlongRay for the general case). distance may be +infinity.
double factor(const Fog& fog, double distance);

// f along the ray origin + t * direction, t in [0, distance]; `direction` need not be unit
// length (a zero direction means distance 0). Distance-based modes use `distance` only.
double factor(const Fog& fog, const glm::dvec3& origin, const glm::dvec3& direction, double distance);

// The same for a ray from height originY whose unit direction has y component dirY.
double factorAtElevation(const Fog& fog, double originY, double dirY, double distance);

// maxOpacity and cutoffDistance applied to the weight f of a point at `distance`.
double engineLimits(const Fog& fog, double distance, double f);

// Directional in-scattering (see Directional): the weight 1 - f_dir of its colour along a ray
// (0 without fog.directional), and its lobe for cos theta = dot(unit view ray, unit direction).
double inscatterWeight(const Fog& fog, double originY, double dirY, double distance);
double lobe(const Directional& d, double cosTheta);

// Per channel: what reaches the eye of the object (transmittance T) and of the fog's own
// colour (S), so that C = object * T + S (+ the glow). Every mode but kAtmospheric has
// T = f and S = (1 - f) * color; kAtmospheric has its own per-channel exponentials, under the
// same start, opacity cap (T >= 1 - maxOpacity, S <= maxOpacity * color) and cutoff (T = 1, S = 0).
glm::dvec3 transmittance(const Fog& fog, double originY, double dirY, double distance);
glm::dvec3 scattered(const Fog& fog, double originY, double dirY, double distance);

// The colour of an object at `point` seen from `eye` through this fog (one fog, no regions):
// object * T + S + inscatterWeight * directional.color * lobe.
glm::dvec3 shade(const Fog& fog, const glm::dvec3& object, const glm::dvec3& eye, const glm::dvec3& point);

// Exact optical depth of density a * e^(-b (y - h)) along the ray from height originY with
// unit-vector y component dirY over length t (t may be +infinity):
//   tau = a * e^(-b (originY - h)) * t * g(b * dirY * t),  g(x) = (1 - e^(-x)) / x,
// evaluated in log space with expm1 so that horizontal rays (x -> 0), extreme b and camera
// heights never overflow to NaN. Returns +infinity when the depth is unbounded.
double heightOpticalDepth(double a, double b, double h, double originY, double dirY, double t);

// The same integral by the midpoint rule with `steps` samples (the ray-marching reference
// the closed form is measured against; t must be finite).
double heightOpticalDepthMarched(double a, double b, double h, double originY, double dirY, double t, int steps);

// Distance where f first reaches 1/255 ("complete to 8 bits"), or its floor 1 - maxOpacity
// when that is higher; infinity if never; cutoffDistance when that is nearer (beyond it the
// fog is gone). For kHeight: along a horizontal ray from cameraHeight.
double completeDistance(const Fog& fog, double cameraHeight = 0.0);

// X3D LocalFog generalised: a region with its own fog. Regions are closed sets (a point on
// the surface is inside). A point takes the innermost region containing it, that is the one
// of smallest volume; between equal volumes the earlier region in the list wins. Outside
// every region the global fog applies. The distance is always viewer-to-point.
struct Region {
  enum class Shape { kBox, kSphere } shape = Shape::kBox;
  glm::dvec3 min{0.0}, max{0.0};  // box, min <= max per axis
  glm::dvec3 center{0.0};         // sphere
  double radius = 0.0;            // sphere, >= 0
  Fog fog;
};
[[nodiscard]] std::optional<Error> validate(const Region& region);
// ln of the region's volume: what "innermost" compares (in log space, so that regions of 1e-200
// and 1e200 compare; -infinity for a flat one).
double logVolume(const Region& region);
// Index of the region that applies at `point`, or -1 for the global fog.
int regionAt(const std::vector<Region>& regions, const glm::dvec3& point);

// What an object at `point` seen from `camera` gets from the fog of the innermost region that
// holds the point (the global fog where none does): C = object * transmittance + fogColor.
// Every length and product is taken so that points 1e-300 or 1e300 away come out as the
// closed form says (no overflow in |point - camera| or d^2).
struct Sample {
  int region = -1;  // the index in `regions`, -1 for the global fog
  double factor = 1.0;
  glm::dvec3 transmittance{1.0}, fogColor{0.0};  // per channel; fogColor holds the glow too
};
Sample sampleAt(const Fog& global, const std::vector<Region>& regions, const glm::dvec3& camera,
                const glm::dvec3& point);

// ---- Colour tables ---------------------------------------------------------------------
// The largest table (entries: size * elevations) the service's contract allows: the top of
// --max-table-size, and the C API's bound on untrusted options.
inline constexpr size_t kMaxTableEntries = size_t(1) << 24;

struct TableOptions {
  size_t size = 0;                             // distance samples N >= 2; 0 = pick the smallest N meeting maxError
  double maxError = 0.0;                       // used when size == 0: largest acceptable interpolation error
  size_t maxSize = 65536;                      // bound on entries (size * elevations)
  std::optional<double> rangeStart, rangeEnd;  // default [0, completeDistance]
  size_t elevations = 0;                       // kHeight only: samples of the ray's y component over [-1, 1];
                                               // 0 = same as size
  double cameraHeight = 0.0;                   // kHeight only
  bool measureError = true;                    // dense-sampling error measurement (~8 evaluations/entry); false: an
                                               // estimate from the table's second differences (size tables only:
                                               // maxError's search is made of measurements)
  // kHeight only. kWarped (the default since 2026-11-28): rows dense near the horizon and each
  // row's columns over its own span, so that f is smooth along both axes (WarpedAxes). kLinear:
  // rows even in the ray's y, columns even in distance (simpler to look up, but a 16 x 16 table
  // is 0.73 off at the horizon). Other fog types ignore it.
  enum class Layout { kLinear, kWarped } layout = Layout::kWarped;
};
const char* toString(TableOptions::Layout layout);  // "linear", "warped"
std::optional<TableOptions::Layout> layoutFromString(const std::string& name);
// Rows of a HEIGHT table of `size` columns: options.elevations if given, else `size` (kLinear,
// square) or half of it (kWarped, at least 2).
size_t tableRows(const TableOptions& options, size_t size);

// A warped HEIGHT table's axes. A lookup for a ray of unit y component y at distance d reads
//   row    v = 1/2 + asinh(rowK y) / (2 asinh rowK)                   (0 = straight down)
//   column u = clamp((d - start) / span, 0, 1)
//   span = end - start                                   when y >= 0 or kappa = 0
//        = smin(end - start, lambda K ln(1 + x) / x)     when y < 0,
//          K = kappa e^(falloff y start), x = -K y, smin(a, b) = m (1 + (m/M)^8)^(-1/8) with m, M
//          the smaller and the larger of a, b
// with start = factorStart for f and S, inscatterStart for the glow. span is lambda times the
// distance at which the steepest layer alone, from its density at the start, would reach the
// table's completeness level
// (f = max(1/255, 1 - maxOpacity)) along that ray: a downward row's columns end where its fog
// is done, however near. kappa is 0 (even columns) for a fog without height dependence, and for
// a camera so far above the fog that kappa would pass e^69 (beyond a float in K x): there the
// downward rows' front is sharper than any column spacing, and the table's maxError says how
// much. rowK puts rows about 1/(falloff span) apart at the horizon, the
// scale on which a distant point's fog changes with elevation.
struct WarpedAxes {
  double rowK = 1.0;
  double falloff = 0.0, kappa = 0.0, lambda = 0.0;
  double factorStart = 0.0, inscatterStart = 0.0, end = 0.0;
};
WarpedAxes warpedAxes(const Fog& fog, double cameraHeight, double rangeStart, double rangeEnd);
double warpedRowY(const WarpedAxes& axes, double v);                // v in [0, 1] -> y
double warpedSpan(const WarpedAxes& axes, double y, double start);  // as above

struct Table {
  size_t width = 0;   // distance samples
  size_t height = 1;  // elevation samples (1 for distance-only fogs)
  double rangeStart = 0.0, rangeEnd = 0.0;
  TableOptions::Layout layout = TableOptions::Layout::kLinear;  // kWarped: entries at warped's axes
  WarpedAxes warped;
  std::vector<float> inscatter;  // with fog.directional: 1 - f_dir at the same samples (else empty)
  std::vector<float> transmittanceRgb, scatteredRgb;  // kAtmospheric: T and S, 3 per sample (else empty)
  std::vector<float> factor;  // row-major [elevation][distance]; kLinear: f at d_i = start + i*(end-start)/(width-1),
                              // dirY_j = -1 + 2j/(height-1); kWarped: at u_i = i/(width-1), v_j = j/(height-1)
  double maxError = 0.0;      // max |lerp(table) - exact| by dense sampling, over f and inscatter (if measured)
  double errorAtDistance = 0.0;
  Stats stats;  // method, elapsedMs (table only), counters: entries, evaluations
};

Result<Table> buildTable(const Fog& fog, const TableOptions& options);

// Max |interpolated - exact| of `table` by dense sampling (subdivisions per interval).
double measureTableError(const Fog& fog, const Table& table, double cameraHeight, int subdivisions,
                         double* where = nullptr);

// ---- The fog in a shader -----------------------------------------------------------
// GLSL without a #version line (valid in GLSL ES 3.00 and 330 core) defining
// vec3 applyFog(vec3 rgb, vec3 world): the colour rgb seen at world position `world`, fogged
// by `global` and `regions` (factor()'s formulas per fragment, in float), with exactly the fog
// types and engine terms they use. effectd's renderer compiles the same text.
struct ShaderVariant {  // what of the GLSL a fog needs; equal variants share a program
  std::vector<FogType> types;  // distinct, sorted
  size_t regions = 0;
  // The engine terms some slot uses: only those are compiled in.
  bool start = false, cutoff = false, opacity = false, secondLayer = false, directional = false;
  bool filament = false, unreal = false;  // some slot follows that engine's convention
  bool engine() const { return start || cutoff || opacity || directional || filament || unreal; }
  std::string key() const;  // e.g. "fog:GL_EXP:r0"
};
ShaderVariant shaderVariant(const Fog& global, const std::vector<Region>& regions);
std::string shaderGlsl(const ShaderVariant& variant);
// The uniforms' values for a camera at `eye`: arrays flattened, slot 0 the global fog, then the
// regions smallest first (as regionAt() picks them).
struct ShaderUniform {
  std::string name, type;  // e.g. "uFogParams", "vec4[3]"
  std::vector<double> values;
};
std::vector<ShaderUniform> shaderUniforms(const Fog& global, const std::vector<Region>& regions,
                                          const glm::dvec3& eye);
struct FogShader {
  std::string glsl;
  std::vector<ShaderUniform> uniforms;
};
FogShader shader(const Fog& global, const std::vector<Region>& regions, const glm::dvec3& eye);


}  // namespace effects::fog
EFFECTS_API_END
