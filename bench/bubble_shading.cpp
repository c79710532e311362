// The bubble's shading: error against run time. Each variant of the GPU shading (the paper's
// model; + its thin-film table; the soap film front only; + its far side; + the lights'
// highlights) against the physical reference (render::referenceRender: the analytic sphere,
// the film per wavelength at 1 nm, both films, the lights), on one scene: a bubble reflecting a
// sky in front of a dark backdrop, the wobble off (the reference traces the sphere). Prints a
// markdown table: frame time p50 (variants compiled, read-back included), mean and p95 CIE76
// Delta E*ab over the bubble's pixels, and the reference's own time and the thickness texture's.
//   build/bench/bubble_shading [iterations=20] [size=512] [PREFIX]
// With PREFIX, also writes PREFIX-reference.png, PREFIX-film.png (the last variant) and
// PREFIX-delta-e.png (Delta E*ab / 20 as grey, red where above 20).
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include <glm/vec3.hpp>
#include <render/render.h>

#include "contract/config.h"
#include "api/scene.h"

namespace {

using nlohmann::json;
namespace rd = effects::render;
namespace bb = effects::bubble;

json sceneOf(int size, const json& bubble) {
  return {{"width", size},
          {"height", size},
          {"time", 7},
          {"camera", {{"position", {0, 0.3, 4}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
          {"background", {{"gradient", {{"top", {0.18, 0.24, 0.2, 1}}, {"bottom", {0.08, 0.1, 0.07, 1}}}}}},
          {"environment", {{"zenith", {0.35, 0.6, 1.0}}, {"horizon", {1.0, 0.98, 0.95}}, {"ground", {0.16, 0.18, 0.12}}}},
          {"bubble", bubble}};
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return 0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, size_t(p * double(v.size() - 1) + 0.5))];
}

// The film's colour alone, against 1 nm sampling over thickness 0-1000 nm x cos 0.02-1: the
// thin-film table (16 wavelengths, 256 x 256, looked up bilinearly between texel centres as the
// shader does) and Belcour & Barla's analytic form, with their CPU cost per colour.
void filmColourTable() {
  bb::ThinFilmOptions o;
  o.measureError = false;
  effects::Stopwatch build;
  const bb::ThinFilmTable table = bb::thinFilmTable(o).value();
  const double buildMs = build.ms();
  auto lookup = [&](double d, double c) {
    const double x = d / o.thicknessMaxNm * (table.width - 1), y = c * (table.height - 1);
    const int x0 = std::min(int(x), table.width - 2), y0 = std::min(int(y), table.height - 2);
    const double fx = x - x0, fy = y - y0;
    glm::dvec3 sum(0);
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < 2; ++i) {
        const float* t = &table.rgb[(size_t(y0 + j) * size_t(table.width) + size_t(x0 + i)) * 3];
        sum += glm::dvec3(t[0], t[1], t[2]) * (i ? fx : 1 - fx) * (j ? fy : 1 - fy);
      }
    return sum;
  };
  std::vector<glm::dvec2> points;  // thickness, cos
  for (int b = 0; b < 32; ++b)
    for (int a = 0; a < 64; ++a) points.push_back({1000.0 * (a + 0.5) / 64, 0.02 + 0.98 * (b + 0.5) / 32});
  std::vector<glm::dvec3> reference, analytic(points.size());
  for (const auto& p : points) reference.push_back(bb::filmColor(o.ior, p.x, p.y, 400));
  effects::Stopwatch timeAnalytic;
  for (size_t i = 0; i < points.size(); ++i) analytic[i] = bb::filmColorAnalytic(o.ior, points[i].x, points[i].y);
  const double analyticNs = timeAnalytic.ms() * 1e6;
  std::vector<double> tableDe, analyticDe;
  for (size_t i = 0; i < points.size(); ++i) {
    tableDe.push_back(bb::deltaE(lookup(points[i].x, points[i].y), reference[i]));
    analyticDe.push_back(bb::deltaE(analytic[i], reference[i]));
  }
  auto mean = [](const std::vector<double>& v) {
    double s = 0;
    for (double x : v) s += x;
    return s / double(v.size());
  };
  const double n = double(tableDe.size());
  std::printf("\n| film colour vs 1 nm sampling | mean Delta E*ab | p95 | max | CPU per colour |\n|---|---|---|---|---|\n");
  std::printf("| table, 16 wavelengths, 256 x 256, bilinear | %.2f | %.2f | %.2f | %.0f ns to build a texel (table %.0f ms); "
              "one texture fetch in the shader |\n",
              mean(tableDe), percentile(tableDe, 0.95), percentile(tableDe, 1.0),
              buildMs * 1e6 / (double(table.width) * table.height), buildMs);
  std::printf("| analytic (Belcour & Barla 2017) | %.2f | %.2f | %.2f | %.0f ns per colour, in the shader per fragment |\n",
              mean(analyticDe), percentile(analyticDe, 0.95), percentile(analyticDe, 1.0), analyticNs / n);
}

}  // namespace

int main(int argc, char** argv) {
  const int iterations = argc > 1 ? std::max(2, std::atoi(argv[1])) : 20;
  const int size = argc > 2 ? std::clamp(std::atoi(argv[2]), 16, 512) : 512;
  effectd::Config config;
  auto renderer = rd::Renderer::create();
  if (!renderer.ok()) {
    std::fprintf(stderr, "bubble_shading: %s\n", renderer.error().message.c_str());
    return 1;
  }
  effects::ThreadPool pool(1);  // the reference on this machine's two cores
  const json still = {{"mesh", {{"level", 4}}}, {"features", {{"wobble", false}}}};
  auto with = [&](const json& features, const char* shading) {
    json b = still;
    b["features"].update(features);
    b["shading"] = shading;
    return b;
  };
  effectd::RequestContext ctx{"bench", config};
  ctx.parallel = &pool;
  rd::Scene referenceScene = effectd::buildScene(sceneOf(size, still), ctx);
  auto ref = rd::referenceRender(referenceScene, &pool);
  if (!ref.ok()) {
    std::fprintf(stderr, "reference: %s\n", ref.error().message.c_str());
    return 1;
  }
  const rd::Reference& reference = ref.value();
  size_t pixels = 0;
  for (uint8_t in : reference.bubble) pixels += in;
  // Pixels at least 3 away from the silhouette, where the mesh's polygon edge cannot differ.
  std::vector<uint8_t> interior(reference.bubble.size(), 0);
  for (int y = 3; y < size - 3; ++y)
    for (int x = 3; x < size - 3; ++x) {
      bool all = true;
      for (int dy = -3; dy <= 3 && all; ++dy)
        for (int dx = -3; dx <= 3 && all; ++dx) all = reference.bubble[size_t(y + dy) * size_t(size) + size_t(x + dx)];
      interior[size_t(y) * size_t(size) + size_t(x)] = all;
    }
  effects::Stopwatch watch;
  const int repeats = 20;
  for (int i = 0; i < repeats; ++i) (void)bb::thicknessField(bb::Params{}, bb::ThicknessOptions{.measureError = false}, 7);
  const double thicknessMs = watch.ms() / repeats;
  std::printf("renderer: %s, %dx%d, %d iterations per variant; Delta E*ab over the %zu pixels of the bubble\n\n",
              renderer.value()->description().c_str(), size, size, iterations, pixels);
  std::printf("| variant | frame p50 | mean Delta E*ab | p95 Delta E*ab | p95, 3 px inside the silhouette |\n"
              "|---|---|---|---|---|\n");
  struct Variant {
    const char* name;
    json bubble;
  };
  for (const Variant& v : {
           Variant{"paper (eqns 3-11)", with(json::object(), "paper")},
           Variant{"paper + film table", with({{"iridescence", true}}, "paper")},
           Variant{"film, near side", with({{"backFace", false}, {"highlight", false}}, "film")},
           Variant{"film + far side", with({{"highlight", false}}, "film")},
           Variant{"film + far side + highlight", with(json::object(), "film")},
       }) {
    std::vector<double> ms;
    rd::Image image;
    for (int i = 0; i <= iterations; ++i) {
      rd::Scene s = effectd::buildScene(sceneOf(size, v.bubble), ctx);
      auto f = renderer.value()->render(s);
      if (!f.ok()) {
        std::fprintf(stderr, "%s: %s\n", v.name, f.error().message.c_str());
        return 1;
      }
      if (i > 0) ms.push_back(f.value().ms);  // the first compiles the variant
      image = std::move(f.value().image);
    }
    std::vector<double> de, inside;
    for (size_t p = 0; p < reference.bubble.size(); ++p)
      if (reference.bubble[p]) {
        const float* b = &reference.image.rgba[p * 4];  // the render as its 8-bit PNG holds it
        de.push_back(bb::deltaE({image.at(p * 4), image.at(p * 4 + 1), image.at(p * 4 + 2)}, {b[0], b[1], b[2]}));
        if (interior[p]) inside.push_back(de.back());
      }
    double mean = 0;
    for (double d : de) mean += d;
    mean /= std::max<size_t>(1, de.size());
    if (argc > 3) {  // the pictures behind the numbers
      rd::Image map{size, size, std::vector<float>(size_t(size) * size_t(size) * 4, 1.0f), {}};
      for (size_t p = 0, k = 0; p < reference.bubble.size(); ++p) {
        const double d = reference.bubble[p] ? de[k++] : 0.0;
        for (int c = 0; c < 3; ++c) map.rgba[p * 4 + size_t(c)] = float(std::min(d / 20, 1.0));
        if (d > 20) map.rgba[p * 4 + 1] = map.rgba[p * 4 + 2] = 0;
      }
      const std::string prefix = argv[3];
      for (auto [name, img] : {std::pair{"-reference.png", &reference.image}, {"-film.png", &image}, {"-delta-e.png", &map}})
        if (auto png = rd::encodePng(*img, 8); png.ok()) std::ofstream(prefix + name, std::ios::binary) << png.value();
    }
    std::printf("| %s | %.1f ms | %.2f | %.2f | %.2f |\n", v.name, percentile(ms, 0.5), mean, percentile(de, 0.95),
                percentile(inside, 0.95));
  }
  std::printf("| reference (CPU, %d wavelengths, 2 threads) | %.0f ms | 0 | 0 | 0 |\n", rd::kReferenceWavelengths,
              reference.ms);
  std::printf("\nthickness texture 128 x 64 (drainage + swirl, one thread): %.1f ms\n", thicknessMs);
  filmColourTable();
  return 0;
}
