// The bubble's physical reference: CPU ray tracing of the analytic sphere with the soap film
// evaluated per wavelength (see render.h, docs/effects.md section 3.5).
#include <algorithm>
#include <cmath>
#include <optional>

#include <glm/geometric.hpp>

#include "render/render.h"

namespace effects::render {
namespace {

using glm::dvec2;
using glm::dvec3;

// The backdrop and the lights as the renderer's passes see them.
struct Surroundings {
  const Scene& scene;
  dvec3 right, up, forward;  // camera basis (world)
  dvec2 tanHalfFov;

  explicit Surroundings(const Scene& s) : scene(s) {
    const Camera& c = s.camera;
    forward = glm::normalize(c.target - c.position);
    right = glm::normalize(glm::cross(forward, c.up));
    up = glm::cross(right, forward);
    const double t = std::tan(c.fovYDeg * 3.14159265358979323846 / 360);
    tanHalfFov = {t * s.width / s.height, t};
  }

  // backgroundAt(uv) of the background pass (uv from the bottom left), premultiplied, opaque.
  dvec3 backdrop(dvec2 uv) const {
    const Background& b = scene.background;
    uv = glm::clamp(uv, dvec2(0), dvec2(1));
    switch (b.kind) {
      case Background::Kind::kColor: return dvec3(b.color) * b.color.a;
      case Background::Kind::kGradient: {
        const glm::dvec4 c = b.bottom + (b.top - b.bottom) * uv.y;
        return dvec3(c) * c.a;
      }
      case Background::Kind::kImage: {  // bilinear, clamped, row 0 at the top
        const Image& im = b.image;
        const double x = uv.x * im.width - 0.5, y = (1 - uv.y) * im.height - 0.5;
        const int x0 = int(std::floor(x)), y0 = int(std::floor(y));
        const double fx = x - x0, fy = y - y0;
        dvec3 sum(0);
        for (int j = 0; j < 2; ++j)
          for (int i = 0; i < 2; ++i) {
            const int xi = std::clamp(x0 + i, 0, im.width - 1), yj = std::clamp(y0 + j, 0, im.height - 1);
            const float* p = &im.rgba[(size_t(yj) * size_t(im.width) + size_t(xi)) * 4];
            sum += dvec3(p[0], p[1], p[2]) * double(p[3]) * (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
          }
        return sum;
      }
    }
    return dvec3(0);
  }

  // The environment cube's lookup (environmentFragment): the scene's sky, or the backdrop where
  // a direction projects to the screen (one behind the camera to its mirror image).
  dvec3 environment(const dvec3& d) const {
    if (scene.environment) return skyAt(*scene.environment, d);
    const double z = -std::abs(glm::dot(d, forward));
    const dvec2 ndc = dvec2(glm::dot(d, right), glm::dot(d, up)) / std::max(-z, 1e-6) / tanHalfFov;
    return backdrop(0.5 * ndc + 0.5);
  }

  // What a mirror direction sees: the environment plus each light's lobe (the film shader's).
  dvec3 mirror(const dvec3& r, const std::vector<bubble::Light>& lights) const {
    dvec3 c = environment(r);
    for (size_t i = 0; i < lights.size() && i < size_t(bubble::kMaxLights); ++i) {
      const bubble::Light& l = lights[i];
      c += l.color * l.intensity *
           std::pow(std::max(glm::dot(r, glm::normalize(l.direction)), 0.0), bubble::highlightSharpness(l));
    }
    return c;
  }
};

std::optional<Error> supported(const Scene& s) {
  if (s.bubbles.empty()) return unsatisfiable("/bubble", "the reference renders a bubble: the scene has none");
  if (s.bubbles.size() > 1) return unsatisfiable("/bubbles", "the reference renders one bubble (no light between bubbles)");
  if (s.lightning) return unsatisfiable("/lightning", "the reference renders the backdrop and the bubble only");
  if (s.fog) return unsatisfiable("/fog", "the reference renders the backdrop and the bubble only");
  if (!s.quads.empty()) return unsatisfiable("/quads", "the reference renders the backdrop and the bubble only");
  if (s.wave) return unsatisfiable("/surfaceWave", "the reference renders the backdrop and the bubble only");
  if (s.blend) return unsatisfiable("/cameraBlend", "the reference renders the backdrop and the bubble only");
  const Bubble& b = s.bubbles.front();
  if (b.features.wobble && b.params.wobbleAmplitude > 0)
    return unsatisfiable("/bubble/features/wobble", "the reference traces the analytic sphere: turn the wobble off");
  return std::nullopt;
}

// The light the two films send towards the camera along d, over the backdrop `behind`; none
// where the ray misses the bubble.
std::optional<dvec3> shade(const Surroundings& env, const Bubble& b, const bubble::SpectrumToRgb& toRgb,
                           const dvec3& eye, const dvec3& d, const dvec3& behind, std::vector<double>& spectra) {
  const dvec3 oc = eye - b.center;
  const double half = glm::dot(oc, d), c = glm::dot(oc, oc) - b.radius * b.radius, disc = half * half - c;
  if (disc <= 0) return std::nullopt;
  const double root = std::sqrt(disc), t1 = -half - root, t2 = -half + root;
  if (t1 <= 0) return std::nullopt;  // the camera inside or past the bubble: not a view this measures
  const dvec3 n1 = (eye + t1 * d - b.center) / b.radius, n2 = (eye + t2 * d - b.center) / b.radius;
  const double cosine = std::clamp(-glm::dot(d, n1), 0.0, 1.0);  // the same at both films (a chord)
  const dvec3 r1 = d - 2 * glm::dot(d, n1) * n1;                   // off the near film
  const dvec3 r2 = d - 2 * glm::dot(d, n2) * n2;                   // off the far film, inside
  const dvec3 n3 = glm::normalize(n2 + 2 * cosine * r2);           // where r2 leaves the sphere
  const bubble::ThicknessOptions& film = b.film;
  const double h1 = bubble::thicknessAt(b.params, film, n1, b.time), h2 = bubble::thicknessAt(b.params, film, n2, b.time),
               h3 = bubble::thicknessAt(b.params, film, n3, b.time);
  const std::vector<double>& nm = toRgb.wavelengthsNm();
  const size_t k = nm.size();
  double* reflected = spectra.data();
  double* through = reflected + k;
  double* backReflected = through + k;
  const double ior = b.params.n2;
  for (size_t i = 0; i < k; ++i) {
    // s and p stay apart: the plane of incidence (the ray and the centre) is the same at every film.
    const dvec2 R1 = bubble::filmReflectanceSP(ior, h1, cosine, nm[i]);
    const dvec2 R2 = bubble::filmReflectanceSP(ior, h2, cosine, nm[i]);
    const dvec2 R3 = bubble::filmReflectanceSP(ior, h3, cosine, nm[i]);
    reflected[i] = (R1.x + R1.y) / 2;
    through[i] = ((1 - R1.x) * (1 - R2.x) + (1 - R1.y) * (1 - R2.y)) / 2;
    backReflected[i] = ((1 - R1.x) * R2.x * (1 - R3.x) + (1 - R1.y) * R2.y * (1 - R3.y)) / 2;
  }
  return toRgb(reflected) * env.mirror(r1, b.lights) + toRgb(through) * behind +
         toRgb(backReflected) * env.mirror(r2, b.lights);
}

}  // namespace

glm::dvec3 skyAt(const Environment& e, const glm::dvec3& d) {
  if (d.y >= 0) return e.horizon + (e.zenith - e.horizon) * std::sqrt(d.y);
  return e.horizon + (e.ground - e.horizon) * std::sqrt(std::min(-4 * d.y, 1.0));
}

Result<Reference> referenceRender(const Scene& scene, Parallel* parallel) {
  if (auto e = supported(scene)) return *e;
  Stopwatch watch;
  const Surroundings env(scene);
  const Bubble& b = scene.bubbles.front();
  const bubble::SpectrumToRgb toRgb(kReferenceWavelengths);
  const dvec3 eye = scene.camera.position;
  const size_t w = size_t(scene.width), h = size_t(scene.height);
  Reference out;
  out.image = Image{scene.width, scene.height, std::vector<float>(w * h * 4, 1.0f), {}};
  out.bubble.assign(w * h, 0);
  forRange(parallel, h, 4, [&](size_t begin, size_t end) {
    std::vector<double> spectra(3 * toRgb.wavelengthsNm().size());
    for (size_t y = begin; y < end; ++y)
      for (size_t x = 0; x < w; ++x) {
        const dvec2 uv((x + 0.5) / double(w), 1 - (y + 0.5) / double(h));
        const dvec2 ndc = 2.0 * uv - 1.0;
        const dvec3 d = glm::normalize(env.forward + ndc.x * env.tanHalfFov.x * env.right +
                                       ndc.y * env.tanHalfFov.y * env.up);
        const dvec3 behind = env.backdrop(uv);
        const std::optional<dvec3> film = shade(env, b, toRgb, eye, d, behind, spectra);
        const dvec3 c = film.value_or(behind);
        float* p = &out.image.rgba[(y * w + x) * 4];
        for (int i = 0; i < 3; ++i) p[i] = float(std::clamp(c[i], 0.0, 1.0));
        out.bubble[y * w + x] = film.has_value();
      }
  });
  out.ms = watch.ms();
  return out;
}

std::vector<double> bubbleDeltaE(const Image& frame, const Reference& reference) {
  std::vector<double> out;
  for (size_t p = 0; p < reference.bubble.size(); ++p) {
    if (!reference.bubble[p]) continue;
    const float* r = &reference.image.rgba[p * 4];
    out.push_back(bubble::deltaE({frame.at(p * 4), frame.at(p * 4 + 1), frame.at(p * 4 + 2)}, {r[0], r[1], r[2]}));
  }
  return out;
}

}  // namespace effects::render
