// POST /v1/render and /v1/scene on whatever EGL offers (llvmpipe without a GPU): example
// scenes against golden images, fog against /v1/fog's tables, lightning pixels against the
// polylines, only-needed passes, concurrency and saturation, bad input.
//
// Golden images are the PNGs in examples/. EFFECTD_UPDATE_GOLDEN=1 rewrites them.
#include <unistd.h>

#include <array>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <future>
#include <tuple>

#include <OpenImageIO/imageio.h>
#include <render/render.h>
#include <glm/geometric.hpp>

#include "../render/internal.h"
#include "api/error_estimates.h"
#include "contract/codec.h"
#include "test_server.h"

namespace effectd::testing {
namespace {

using nlohmann::json;
namespace rd = effects::render;
namespace fs = std::filesystem;

rd::Image decode(const std::string& png) {
  auto img = rd::decodeImage(png, size_t(1) << 28);
  EXPECT_TRUE(img.ok()) << (img.ok() ? "" : img.error().message);
  return img.ok() ? img.value() : rd::Image{};
}

glm::vec4 pixel(const rd::Image& img, int x, int y) {
  const float* p = &img.rgba[(size_t(y) * img.width + x) * 4];
  return {p[0], p[1], p[2], p[3]};
}

httplib::Result render(const TestServer& s, const json& scene) { return s.postJson("/v1/render", scene); }

// Frames of an animated GIF, decoded by OpenImageIO's reader (giflib), as straight RGBA.
std::vector<rd::Image> decodeGif(const std::string& bytes) {
  std::vector<rd::Image> frames;
  // OpenImageIO's GIF reader reads files only.
  const fs::path path = fs::temp_directory_path() / ("effectd-test-" + std::to_string(::getpid()) + ".gif");
  std::ofstream(path, std::ios::binary) << bytes;
  auto in = OIIO::ImageInput::open(path.string());
  fs::remove(path);
  if (!in) return frames;
  for (int i = 0; in->seek_subimage(i, 0); ++i) {
    const OIIO::ImageSpec& s = in->spec();
    rd::Image f{s.width, s.height, std::vector<float>(size_t(s.width) * s.height * 4, 1.0f)};
    if (!in->read_image(i, 0, 0, std::min(4, s.nchannels), OIIO::TypeDesc::FLOAT, f.rgba.data(), 4 * sizeof(float)))
      break;
    frames.push_back(std::move(f));
  }
  return frames;
}

double meanBrightness(const rd::Image& img) {
  double sum = 0;
  for (size_t i = 0; i < img.rgba.size(); ++i)
    if (i % 4 < 3) sum += img.rgba[i];
  return sum / double(img.rgba.size() * 3 / 4);
}

TEST(Render, ExampleScenesMatchTheirGoldenImages) {
  TestServer s;
  const bool update = std::getenv("EFFECTD_UPDATE_GOLDEN") != nullptr;
  int scenes = 0;
  // The scenes and goldens: EFFECTD_EXAMPLES_DIR in the environment (a build copied to another
  // machine without the source tree), else the source tree's examples/.
  const char* examples = std::getenv("EFFECTD_EXAMPLES_DIR");
  for (const auto& entry : fs::directory_iterator(examples ? examples : EFFECTD_EXAMPLES_DIR)) {
    if (entry.path().extension() != ".json") continue;
    ++scenes;
    SCOPED_TRACE(entry.path().filename().string());
    auto r = s.postJson("/v1/render", slurp(entry.path()));
    ASSERT_TRUE(r);
    ASSERT_EQ(r->status, 200) << r->body;
    const bool animated = r->get_header_value("Content-Type") == "image/gif";
    EXPECT_TRUE(animated || r->get_header_value("Content-Type") == "image/png");
    EXPECT_FALSE(r->get_header_value("X-Renderer").empty());
    const fs::path golden = fs::path(entry.path()).replace_extension(animated ? ".gif" : ".png");
    if (update) {
      std::ofstream(golden, std::ios::binary) << r->body;
      continue;
    }
    ASSERT_TRUE(fs::exists(golden)) << golden << " is missing: run with EFFECTD_UPDATE_GOLDEN=1";
    const auto frames = [&](const std::string& bytes) {
      return animated ? decodeGif(bytes) : std::vector<rd::Image>{decode(bytes)};
    };
    const std::vector<rd::Image> got = frames(r->body), want = frames(slurp(golden));
    ASSERT_EQ(got.size(), want.size());
    for (size_t f = 0; f < got.size(); ++f) {
      SCOPED_TRACE("frame " + std::to_string(f));
      ASSERT_EQ(got[f].width, want[f].width);
      ASSERT_EQ(got[f].height, want[f].height);
      // Tolerance: llvmpipe builds and GPUs may differ by rounding at edges, not in content.
      double sum = 0;
      size_t far = 0;
      for (size_t i = 0; i < got[f].rgba.size(); ++i) {
        double d = std::abs(got[f].rgba[i] - want[f].rgba[i]);
        sum += d;
        far += d > 8.0 / 255;
      }
      EXPECT_LT(sum / double(got[f].rgba.size()), 1.0 / 255) << "mean difference";
      EXPECT_LT(double(far) / double(got[f].rgba.size()), 0.005) << "share of channels off by more than 8/255";
    }
  }
  EXPECT_GE(scenes, 4);
}

// A camera at the origin looking down -z; small quads facing it at the table's sample
// distances, spread over the frame. Each quad's centre pixel must show the table's colour.
void expectFogMatchesTable(const TestServer& s, const json& fogDef, int elevations, double cameraHeight) {
  const double range = 40;
  const int size = 9;
  json tableReq = {
      {"fog", fogDef}, {"table", {{"size", size}, {"range", {0, range}}}}, {"objectColors", {{0.9, 0.6, 0.2}}}};
  if (elevations) {
    tableReq["table"]["elevations"] = elevations;
    tableReq["table"]["cameraHeight"] = cameraHeight;
    tableReq["table"]["layout"] = "linear";  // its middle row is the horizontal ray
  }
  auto t = s.postJson("/v1/fog", tableReq);
  ASSERT_TRUE(t);
  ASSERT_EQ(t->status, 200) << t->body;
  const json table = json::parse(t->body)["table"];
  const json& colors = table["finalColors"][0];
  const int row = elevations ? elevations / 2 : 0;  // the horizontal ray's row (dirY = 0)

  const int W = 256, H = 128;
  json scene = {{"width", W},
                {"height", H},
                {"camera", {{"position", {0, cameraHeight, 0}}, {"target", {0, cameraHeight, -1}}, {"fovY", 60}}},
                {"background", {{"color", {0, 0, 0}}}},
                {"fog", {{"fog", fogDef}}},
                {"quads", json::array()}};
  const double aspect = double(W) / H, tanHalf = std::tan(30.0 * M_PI / 180);
  std::vector<std::pair<int, int>> centres;
  for (int i = 1; i < size; ++i) {
    const double d = range * i / (size - 1);
    const double ndcX = -0.85 + 1.7 * (i - 1) / (size - 2);  // spread across the frame
    const double angle = std::atan(ndcX * tanHalf * aspect);
    const glm::dvec3 dir(std::sin(angle), 0, -std::cos(angle));
    const glm::dvec3 c = glm::dvec3(0, cameraHeight, 0) + dir * d;
    scene["quads"].push_back({{"center", {c.x, c.y, c.z}},
                              {"normal", {-dir.x, 0, -dir.z}},
                              {"size", {0.02 * d, 0.02 * d}},
                              {"color", {0.9, 0.6, 0.2}}});
    centres.emplace_back(int(std::floor((ndcX * 0.5 + 0.5) * W)), H / 2);
  }
  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_NE(r->get_header_value("X-Render-Passes").find("quads+fog"), std::string::npos);
  rd::Image img = decode(r->body);
  for (int i = 1; i < size; ++i) {
    auto [x, y] = centres[size_t(i - 1)];
    glm::vec4 got = pixel(img, x, y);
    for (int c = 0; c < 3; ++c) {
      const double want = colors[size_t(row * size + i) * 3 + size_t(c)].get<double>();
      EXPECT_NEAR(got[c], want, 2.0 / 255)
          << fogDef.dump() << " distance " << range * i / (size - 1) << " channel " << c;
    }
  }
}

TEST(Render, FogInARenderMatchesTheFogTableColours) {
  TestServer s;
  expectFogMatchesTable(s, {{"fogType", "DISTANCE_EXP2"}, {"color", {0.5, 0.6, 0.7}}, {"distanceCoefficient", 0.002}},
                        0, 0);
  expectFogMatchesTable(s, {{"fogType", "EXPONENTIAL"}, {"color", {0.2, 0.3, 0.4}}, {"visibilityRange", 60}}, 0, 0);
  expectFogMatchesTable(s, {{"fogType", "GL_LINEAR"}, {"color", {0.8, 0.8, 0.8}}, {"start", 5}, {"end", 35}}, 0, 0);
  expectFogMatchesTable(
      s, {{"fogType", "DISTANCE_GAUSSIAN"}, {"color", {0.1, 0.1, 0.1}}, {"distanceCoefficient", 0.001}}, 0, 0);
  expectFogMatchesTable(
      s,
      {{"fogType", "HEIGHT"}, {"color", {0.6, 0.6, 0.7}}, {"density", 0.08}, {"heightFalloff", 0.5}, {"baseHeight", 0}},
      3, 1.5);
  expectFogMatchesTable(s,
                        {{"fogType", "ATMOSPHERIC"},
                         {"color", {0.9, 0.7, 0.5}},
                         {"extinction", {0.02, 0.05, 0.09}},
                         {"inscattering", {0.01, 0.04, 0.08}}},
                        0, 0);
  // Engine terms: a clear first stretch, a ceiling on opacity, nothing fogged past the cutoff
  // (the last three quads), and height fog's second layer.
  expectFogMatchesTable(s,
                        {{"fogType", "GL_EXP"},
                         {"color", {0.7, 0.75, 0.8}},
                         {"density", 0.08},
                         {"startDistance", 8},
                         {"maxOpacity", 0.7},
                         {"cutoffDistance", 27}},
                        0, 0);
  expectFogMatchesTable(s,
                        {{"fogType", "HEIGHT"},
                         {"color", {0.6, 0.6, 0.7}},
                         {"density", 0.08},
                         {"heightFalloff", 0.5},
                         {"startDistance", 6},
                         {"maxOpacity", 0.9},
                         {"secondLayer", {{"density", 0.03}, {"heightFalloff", 0.1}, {"baseHeight", 2}}}},
                        3, 1.5);
}

// A sun low ahead: each quad's centre pixel must be the fog's colour (the table's final colour)
// plus the glow, inscatter * colour * lobe(angle to the sun), from the same answer.
TEST(Render, FogGlowsTowardsTheSun) {
  TestServer s;
  const json fogDef = {
      {"fogType", "GL_EXP"},
      {"color", {0.25, 0.3, 0.4}},
      {"density", 0.04},
      {"startDistance", 3},
      {"directional", {{"color", {1.2, 0.6, 0.2}}, {"direction", {0.5, 0, -1}}, {"g", 0.5}, {"startDistance", 6}}}};
  const double range = 40;
  const int size = 9;
  auto t = s.postJson(
      "/v1/fog",
      json{{"fog", fogDef}, {"table", {{"size", size}, {"range", {0, range}}}}, {"objectColors", {{0.1, 0.1, 0.1}}}});
  ASSERT_EQ(t->status, 200) << t->body;
  const json table = json::parse(t->body)["table"];
  const int W = 256, H = 128;
  json scene = {{"width", W},
                {"height", H},
                {"camera", {{"position", {0, 0, 0}}, {"target", {0, 0, -1}}, {"fovY", 60}}},
                {"background", {{"color", {0, 0, 0}}}},
                {"fog", {{"fog", fogDef}}},
                {"quads", json::array()}};
  const double aspect = double(W) / H, tanHalf = std::tan(30.0 * M_PI / 180);
  const glm::dvec3 toSun = glm::normalize(glm::dvec3(0.5, 0, -1));
  std::vector<std::tuple<int, int, glm::dvec3>> expected;
  for (int i = 1; i < size; ++i) {
    const double d = range * i / (size - 1);
    const double ndcX = -0.85 + 1.7 * (i - 1) / (size - 2);
    const double angle = std::atan(ndcX * tanHalf * aspect);
    const glm::dvec3 dir(std::sin(angle), 0, -std::cos(angle)), c = dir * d;
    scene["quads"].push_back({{"center", {c.x, c.y, c.z}},
                              {"normal", {-dir.x, 0, -dir.z}},
                              {"size", {0.02 * d, 0.02 * d}},
                              {"color", {0.1, 0.1, 0.1}}});
    const double g = 0.5, cosT = glm::dot(dir, toSun), den = (1 - g) * (1 - g) + 2 * g * (1 - cosT);
    const double lobe = (1 - g) * (1 + g) / (den * std::sqrt(den));
    glm::dvec3 want;
    for (int k = 0; k < 3; ++k)
      want[k] =
          table["finalColors"][0][size_t(i) * 3 + size_t(k)].get<double>() +
          table["inscatter"][size_t(i)].get<double>() * fogDef["directional"]["color"][size_t(k)].get<double>() * lobe;
    expected.emplace_back(int(std::floor((ndcX * 0.5 + 0.5) * W)), H / 2, want);
  }
  auto r = render(s, scene);
  ASSERT_EQ(r->status, 200) << r->body;
  rd::Image img = decode(r->body);
  for (const auto& [x, y, want] : expected) {
    glm::vec4 got = pixel(img, x, y);
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(got[c], std::min(want[c], 1.0), 2.0 / 255) << x << " channel " << c;
  }
}

// Filament's and Unreal's conventions drawn by the GPU: quads looked at from 2 units up, on rays
// up and down and at distances before the start and in the fog, each centre pixel the colour of
// the answer's sample at that point (object * T + S + glow).
TEST(Render, FogConventionsDrawAsTheirSamples) {
  TestServer s;
  const int W = 256, H = 128;
  const double aspect = double(W) / H, tanHalf = std::tan(30.0 * M_PI / 180), cameraY = 2;
  const glm::dvec3 quadColor(0.9, 0.6, 0.2);
  for (const char* convention : {"filament", "unreal"}) {
    const json fogDef = {
        {"fogType", "HEIGHT"},
        {"convention", convention},
        {"color", {0.55, 0.6, 0.7}},
        {"density", 0.06},
        {"heightFalloff", 0.3},
        {"startDistance", 4},
        {"maxOpacity", 0.9},
        {"directional",
         {{"color", {1.5, 0.8, 0.3}}, {"direction", {0.3, 0.2, -1}}, {"exponent", 6}, {"startDistance", 5}}}};
    json scene = {{"width", W},
                  {"height", H},
                  {"camera", {{"position", {0, cameraY, 0}}, {"target", {0, cameraY, -1}}, {"fovY", 60}}},
                  {"background", {{"color", {0, 0, 0}}}},
                  {"fog", {{"fog", fogDef}}},
                  {"quads", json::array()}};
    json points = json::array();
    std::vector<std::pair<int, int>> pixels;
    for (int row = 0; row < 4; ++row)
      for (int col = 0; col < 6; ++col) {
        const double ndcX = -0.8 + 1.6 * col / 5, ndcY = -0.6 + 1.2 * row / 3;
        const double d = 3 + 37.0 * (row * 6 + col) / 23;
        const glm::dvec3 dir = glm::normalize(glm::dvec3(ndcX * tanHalf * aspect, ndcY * tanHalf, -1));
        const glm::dvec3 c = glm::dvec3(0, cameraY, 0) + dir * d;
        scene["quads"].push_back({{"center", {c.x, c.y, c.z}},
                                  {"normal", {-dir.x, -dir.y, -dir.z}},
                                  {"size", {0.03 * d, 0.03 * d}},
                                  {"color", {quadColor.r, quadColor.g, quadColor.b}}});
        points.push_back({c.x, c.y, c.z});
        pixels.emplace_back(int(std::floor((ndcX * 0.5 + 0.5) * W)), int(std::floor((0.5 - ndcY * 0.5) * H)));
      }
    auto a = s.postJson("/v1/fog", json{{"fog", fogDef},
                                        {"include", {"samples"}},
                                        {"samples", {{"camera", {0, cameraY, 0}}, {"points", points}}}});
    ASSERT_EQ(a->status, 200) << a->body;
    const json samples = json::parse(a->body)["samples"];
    auto r = render(s, scene);
    ASSERT_EQ(r->status, 200) << r->body;
    rd::Image img = decode(r->body);
    for (size_t i = 0; i < pixels.size(); ++i) {
      const glm::vec4 got = pixel(img, pixels[i].first, pixels[i].second);
      for (int c = 0; c < 3; ++c) {
        const double want = quadColor[c] * samples[i]["transmittance"][size_t(c)].get<double>() +
                            samples[i]["fogColor"][size_t(c)].get<double>();
        EXPECT_NEAR(got[c], std::min(want, 1.0), 2.0 / 255) << convention << " quad " << i << " channel " << c;
      }
    }
  }
}

double segmentDistance(glm::dvec2 p, glm::dvec2 a, glm::dvec2 b) {
  glm::dvec2 ab = b - a;
  double t = glm::dot(ab, ab) > 0 ? std::clamp(glm::dot(p - a, ab) / glm::dot(ab, ab), 0.0, 1.0) : 0.0;
  return glm::length(p - (a + t * ab));
}

TEST(Render, LightningBrightPixelsLieAlongThePolyline) {
  TestServer s;
  const int W = 256, H = 256;
  json scene = {{"width", W},
                {"height", H},
                {"background", {{"color", {0, 0, 0}}}},
                {"lightning",
                 {{"grid", {{"width", 64}, {"height", 64}}}, {"start", {32, 0}}, {"targets", {{32, 63}}}, {"seed", 5}}},
                {"lightningStyle", {{"coreWidth", 1.5}, {"glowSigma", 0}}}};
  auto data = s.postJson("/v1/scene", scene);
  ASSERT_TRUE(data);
  ASSERT_EQ(data->status, 200) << data->body;
  const json lines = json::parse(data->body)["lightning"]["polylines"];
  std::vector<std::pair<glm::dvec2, glm::dvec2>> segments;
  const double scale = double(W) / 64;
  for (const auto& l : lines)
    for (size_t i = 2; i + 1 < l["points"].size(); i += 2)
      segments.push_back({glm::dvec2(l["points"][i - 2], l["points"][i - 1]) * scale,
                          glm::dvec2(l["points"][i], l["points"][i + 1]) * scale});
  ASSERT_FALSE(segments.empty());

  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const std::string passes = r->get_header_value("X-Render-Passes");
  EXPECT_EQ(passes, "background,lightning,lightningComposite") << "no blur pass without glow";
  rd::Image img = decode(r->body);
  int bright = 0;
  // Main channel half width 1.5 px, plus the anti-aliasing pixel and the half-width caps.
  const double reach = 1.5 + 1.0 + 0.75;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x) {
      if (pixel(img, x, y).b < 0.25f) continue;
      ++bright;
      glm::dvec2 p(x + 0.5, y + 0.5);
      double best = 1e9;
      for (const auto& [a, b] : segments) best = std::min(best, segmentDistance(p, a, b));
      ASSERT_LE(best, reach) << "bright pixel (" << x << ", " << y << ") away from every segment";
    }
  // And the bolt is really there: its main channel is bright along its length.
  EXPECT_GT(bright, H) << "a bolt from top to bottom lights at least one pixel per row";
  int lit = 0, checked = 0;
  for (const auto& [a, b] : segments) {
    glm::dvec2 m = (a + b) * 0.5;
    ++checked;
    lit += pixel(img, int(m.x), int(m.y)).b > 0.2f;
  }
  EXPECT_GT(lit, checked * 8 / 10) << "segment midpoints lit";

  scene["lightningStyle"]["glowSigma"] = 4;
  r = render(s, scene);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->get_header_value("X-Render-Passes"),
            "background,lightning,blurHorizontal,blurVertical,lightningComposite");
}

TEST(Render, OnlyThePassesAndCodeTheSceneNeeds) {
  // No fog: no fog code in any composed shader; fog: only the types used.
  EXPECT_EQ(rd::detail::quadFragment(nullptr).find("Fog"), std::string::npos);
  rd::Fog fog;
  fog.global.type = effects::fog::FogType::kGlExp;
  auto v = effects::fog::shaderVariant(fog.global, fog.regions);
  const std::string withFog = rd::detail::quadFragment(&v);
  EXPECT_NE(withFog.find("applyFog"), std::string::npos);
  EXPECT_NE(withFog.find("GL_EXP"), std::string::npos);
  EXPECT_EQ(withFog.find("fogLogG"), std::string::npos) << "height-fog code only for HEIGHT";
  EXPECT_EQ(withFog.find("uRegionLo"), std::string::npos) << "region code only with regions";
  EXPECT_EQ(rd::detail::compositeFragment(false).find("uGlow"), std::string::npos);

  Config uncached = TestServer::quietConfig();
  uncached.responseCacheMb = 0;  // every request renders: the compile counts are what is tested
  TestServer s(uncached);
  json scene = {{"width", 64}, {"height", 64}, {"quads", {{{"center", {0, 0.5, 0}}, {"size", {1, 1}}}}}};
  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("X-Render-Passes"), "background,quads");
  EXPECT_NE(r->get_header_value("X-Shader-Variants-Compiled"), "0");
  // Variants are cached per context: the same scene again compiles nothing on that thread.
  // (Two render threads: render until both have served it.)
  for (int i = 0; i < 4; ++i) r = render(s, scene);
  EXPECT_EQ(r->get_header_value("X-Shader-Variants-Compiled"), "0");
  auto m = s.client().Get("/metrics");
  ASSERT_TRUE(m);
  EXPECT_NE(m->body.find("render_passes_total{kind=\"quads\"}"), std::string::npos) << m->body;
  EXPECT_EQ(m->body.find("blurHorizontal"), std::string::npos) << "no lightning, no blur pass";

  scene["fog"] = {{"fog", {{"fogType", "GL_EXP"}, {"density", 0.1}}}};
  r = render(s, scene);
  ASSERT_TRUE(r);
  EXPECT_EQ(r->get_header_value("X-Render-Passes"), "background,quads+fog");

  auto ready = s.client().Get("/readyz");
  ASSERT_TRUE(ready);
  EXPECT_EQ(ready->status, 200);
  EXPECT_FALSE(json::parse(ready->body)["info"].value("renderer", "").empty()) << ready->body;
}

// The on-screen radius in pixels of the unit sphere seen from 4 units with a 45-degree field
// of view, in an n x n frame.
double discRadius(int n) { return std::tan(std::asin(0.25)) / std::tan(22.5 * M_PI / 180) * n / 2; }

// The default bubble is a soap film: reflecting a sky in front of a dark backdrop it changes
// most of its disc, in many hues (the paper's shader with the old example changed 6 % of it, in
// one or two); it only reflects and transmits: with nothing to reflect it leaves the backdrop as
// it is (a lossless film over an environment equal to what is behind it is nearly invisible).
TEST(Render, FilmBubbleShowsBandsOfColourOverItsFace) {
  TestServer s;
  const int n = 192;
  json scene = {{"width", n},
                {"height", n},
                {"time", 7},
                {"camera", {{"position", {0, 0, 4}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
                {"background", {{"color", {0.1, 0.1, 0.1, 1}}}},
                {"environment", json::object()},  // the default sky
                {"bubble", {{"mesh", {{"level", 4}}}}}};
  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_NE(r->get_header_value("X-Render-Passes").find("bubble-film"), std::string::npos);
  const rd::Image img = decode(r->body);
  const double disc = discRadius(n);
  int inside = 0, changed = 0;
  std::array<int, 6> hues{};
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      if (std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0) > 0.9 * disc) continue;
      ++inside;
      const glm::vec4 c = pixel(img, x, y);
      const float mx = std::max({c.r, c.g, c.b}), mn = std::min({c.r, c.g, c.b});
      if (std::max({std::abs(c.r - 0.1f), std::abs(c.g - 0.1f), std::abs(c.b - 0.1f)}) > 0.02f) ++changed;
      if (mx - mn > 0.015f) {  // a visible tint: which sixth of the hue circle
        const double h = std::atan2(std::sqrt(3.0) * (c.g - c.b), 2.0 * c.r - c.g - c.b) + M_PI;
        ++hues[std::min(5, int(h / (2 * M_PI) * 6))];
      }
    }
  ASSERT_GT(inside, 1000);
  EXPECT_GT(changed, inside / 2) << changed << " of " << inside;
  int huesSeen = 0;
  for (int h : hues) huesSeen += h > inside / 50;
  EXPECT_GE(huesSeen, 4) << ::testing::PrintToString(hues);

  // The far side adds its own reflection through the near side.
  json front = scene;
  front["bubble"]["features"] = {{"backFace", false}};
  const rd::Image frontOnly = decode(render(s, front)->body);
  EXPECT_NE(frontOnly.rgba, img.rgba);

  // Nothing to reflect, nothing drawn: the film adds no light of its own.
  json dark = scene;
  dark["background"] = {{"color", {0, 0, 0, 1}}};
  dark.erase("environment");
  dark["bubble"]["features"] = {{"highlight", false}};
  const rd::Image black = decode(render(s, dark)->body);
  float brightest = 0;
  for (size_t i = 0; i < black.rgba.size(); i += 4)
    brightest = std::max({brightest, black.rgba[i], black.rgba[i + 1], black.rgba[i + 2]});
  EXPECT_LT(brightest, 0.01f);
}

// reference: true ray traces the bubble on the CPU; the GPU's film shading stays close to it
// (docs/error-vs-time.md measures every variant), and what it cannot trace is refused.
TEST(Render, ReferenceRenderAgreesWithTheFilmShader) {
  TestServer s;
  const int n = 96;
  json scene = {{"width", n},
                {"height", n},
                {"time", 7},
                {"camera", {{"position", {0, 0, 4}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
                {"background", {{"gradient", {{"top", {0.2, 0.25, 0.2, 1}}, {"bottom", {0.05, 0.05, 0.05, 1}}}}}},
                {"environment", json::object()},
                {"bubble", {{"mesh", {{"level", 5}}}, {"features", {{"wobble", false}}}}}};
  auto gpu = render(s, scene);
  json ref = scene;
  ref["reference"] = true;
  auto traced = render(s, ref);
  ASSERT_TRUE(gpu && traced);
  ASSERT_EQ(traced->status, 200) << traced->body;
  EXPECT_EQ(traced->get_header_value("X-Effect-Method"), "reference");
  const rd::Image a = decode(gpu->body), b = decode(traced->body);
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  double sum = 0, outside = 0;
  int count = 0;
  const double disc = discRadius(n);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      const glm::vec4 p = pixel(a, x, y), q = pixel(b, x, y);
      const double de = effects::bubble::deltaE(glm::dvec3(p), glm::dvec3(q));
      if (std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0) < 0.95 * disc)
        sum += de, ++count;
      else if (std::hypot(x + 0.5 - n / 2.0, y + 0.5 - n / 2.0) > 1.1 * disc)
        outside = std::max(outside, de);
    }
  EXPECT_LT(outside, 1.5) << "the backdrop is the same picture";
  EXPECT_LT(sum / count, 4.0) << "mean Delta E*ab over the bubble";

  for (auto [field, value, status] :
       {std::tuple{
            "/lightning",
            json{{"grid", {{"width", 16}, {"height", 16}}}, {"start", {8, 0}}, {"targets", json::array({json{8, 15}})}},
            422},
        std::tuple{"/frames", json{{"count", 2}}, 422}}) {
    json bad = ref;
    bad[std::string(field).substr(1)] = value;
    json p = expectProblem(render(s, bad), status);
    EXPECT_TRUE(hasPointer(p, field)) << p.dump();
  }
  json wobbling = ref;
  wobbling["bubble"]["features"]["wobble"] = true;
  EXPECT_TRUE(hasPointer(expectProblem(render(s, wobbling), 422), "/bubble/features/wobble"));
  json big = ref;
  big["width"] = big["height"] = 1024;
  EXPECT_TRUE(hasPointer(expectProblem(render(s, big), 413), "/width"));
}

// measureError: the frame's bubble against the reference, in X-Effect-Error, with the reference's
// time as Server-Timing's error stage; a scene the reference cannot trace is refused first.
TEST(Render, MeasureErrorComparesTheFrameWithTheReference) {
  TestServer s;
  const int n = 64;
  json scene = {{"width", n},
                {"height", n},
                {"time", 7},
                {"measureError", true},
                {"camera", {{"position", {0, 0, 4}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
                {"background", {{"gradient", {{"top", {0.2, 0.25, 0.2, 1}}, {"bottom", {0.05, 0.05, 0.05, 1}}}}}},
                {"bubble", {{"mesh", {{"level", 5}}}, {"features", {{"wobble", false}}}}}};
  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  const std::string error = r->get_header_value("X-Effect-Error"), timing = r->get_header_value("Server-Timing");
  ASSERT_NE(error.find("kind=measured"), std::string::npos) << error;
  const double mean = std::stod(error.substr(error.find("meanDeltaE=") + 11));
  EXPECT_GT(mean, 0.0) << error;  // a shader, not the trace itself
  EXPECT_LT(mean, 4.0) << error;  // as ReferenceRenderAgreesWithTheFilmShader
  EXPECT_NE(timing.find("error;dur="), std::string::npos) << timing;
  json plain = scene;
  plain.erase("measureError");
  auto p = render(s, plain);
  ASSERT_TRUE(p);
  // Not measured: the shading variant's figure from the error report, said to be an estimate.
  const std::string estimate = p->get_header_value("X-Effect-Error");
  EXPECT_EQ(estimate.find("kind=measured"), std::string::npos) << estimate;
  char stated[96];  // the report's figure and limit for the default film shading (its data, embedded)
  const effectd::ErrorEstimate film = effectd::shadingErrorEstimate(effects::bubble::Features{});
  ASSERT_TRUE(std::isfinite(film.value));
  std::snprintf(stated, sizeof stated, "pass=bubble; meanDeltaE=%.3g; limit=%g; kind=estimate", film.value, film.limit);
  EXPECT_NE(estimate.find(stated), std::string::npos) << estimate;
  EXPECT_EQ(p->body, r->body);  // the same frame
  json bad = scene;
  bad["lightning"] = {
      {"grid", {{"width", 16}, {"height", 16}}}, {"start", {8, 0}}, {"targets", json::array({json{8, 15}})}};
  EXPECT_TRUE(hasPointer(expectProblem(render(s, bad), 422), "/lightning"));
  // Every effect drawn has its entry, in the scene's order of kinds; a backdrop alone has none.
  json all = bad;
  all.erase("measureError");
  all["fog"] = {{"fog", {{"fogType", "GL_EXP2"}, {"density", 0.05}}}};
  auto a = render(s, all);
  ASSERT_TRUE(a);
  ASSERT_EQ(a->status, 200) << a->body;
  const std::string entries = a->get_header_value("X-Effect-Error");
  const size_t bubble = entries.find("pass=bubble;"), fog = entries.find(", pass=fog; maxSteps8bit="),
               bolt = entries.find(", pass=lightning; maxOffsetPx=1.75; limit=1.75; kind=bound");
  EXPECT_TRUE(bubble == 0 && fog != std::string::npos && bolt != std::string::npos && bubble < fog && fog < bolt)
      << entries;
  json backdrop = plain;
  backdrop.erase("bubble");
  auto b = render(s, backdrop);
  ASSERT_TRUE(b);
  EXPECT_FALSE(b->has_header("X-Effect-Error"));
}

// A depth range of 1e14 (near 1e-7, far 1e7) put the whole scene at depth 1 and the depth test
// dropped the bubble; the renderer narrows the range to what the scene holds, so the frame is
// the one the ordinary planes give, and planes that cut the bubble still cut it.
TEST(Render, ExtremeNearAndFarPlanesKeepTheScene) {
  TestServer s;
  json scene = {{"width", 64},
                {"height", 64},
                {"time", 7},
                {"camera", {{"position", {0, 0.3, 4}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
                {"background", {{"gradient", {{"top", {0.2, 0.25, 0.2, 1}}, {"bottom", {0.05, 0.05, 0.05, 1}}}}}},
                {"environment", {{"zenith", {0.35, 0.6, 1.0}}, {"horizon", {1.0, 0.98, 0.95}}}},
                {"bubble", {{"mesh", {{"level", 4}}}, {"features", {{"wobble", false}}}}},
                {"quads", {{{"center", {0, -1.2, 0}}, {"normal", {0, 1, 0}}, {"up", {0, 0, -1}}, {"size", {6, 6}}}}}};
  auto ordinary = render(s, scene);
  ASSERT_EQ(ordinary->status, 200) << ordinary->body;
  json extreme = scene;
  extreme["camera"]["near"] = 1e-7;
  extreme["camera"]["far"] = 1e7;
  auto e = render(s, extreme);
  ASSERT_EQ(e->status, 200) << e->body;
  const rd::Image a = decode(ordinary->body), b = decode(e->body);
  int differ = 0;
  ASSERT_EQ(a.rgba.size(), b.rgba.size());
  for (size_t i = 0; i < a.rgba.size(); ++i) differ += std::abs(a.rgba[i] - b.rgba[i]) > 1.5f / 255;
  EXPECT_EQ(differ, 0);
  json background = scene;
  background.erase("bubble");
  background.erase("quads");
  const rd::Image bg = decode(render(s, background)->body);
  EXPECT_NE(b.rgba, bg.rgba) << "the bubble and the floor are drawn";
  json cut = scene;
  cut["camera"]["far"] = 3.5;  // the far plane before the bubble's centre: its far half is gone
  EXPECT_NE(decode(render(s, cut)->body).rgba, a.rgba);
  // A floor as most scenes give it, its up left at the default (along its normal): the range
  // still holds all of it, so the floor far behind the bubble is the floor without the bubble.
  json floor = scene;
  floor["quads"] = {{{"center", {0, -1.2, -40}}, {"normal", {0, 1, 0}}, {"size", {200, 200}}}};
  const rd::Image withBubble = decode(render(s, floor)->body);
  floor.erase("bubble");
  const rd::Image alone = decode(render(s, floor)->body);
  for (int x : {0, 3, 6, 57, 60, 63}) {  // beside the bubble (columns 11 to 52), the floor behind it
    const glm::vec4 p = pixel(withBubble, x, 30), q = pixel(alone, x, 30);
    EXPECT_NEAR(p.r, q.r, 1.5 / 255) << "x " << x;
    EXPECT_NEAR(p.g, q.g, 1.5 / 255) << "x " << x;
  }
}

// A cluster: every bubble drawn (far to near), each with its own age; /v1/scene answers each;
// problems name the bubble they are in.
TEST(Render, SeveralBubblesAreDrawnAndAnswered) {
  TestServer s;
  json scene = {{"width", 96},
                {"height", 64},
                {"camera", {{"position", {0, 0, 6}}, {"target", {0, 0, 0}}}},
                {"environment", json::object()},
                {"bubbles",
                 {{{"center", {-1.2, 0, 0}}, {"bubble", {{"time", 0}}}},
                  {{"center", {1.2, 0, -1}}, {"bubble", {{"time", 30}, {"mesh", {{"radius", 0.5}}}}}}}}};
  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_EQ(r->get_header_value("X-Render-Passes"), "background,environment,bubble-film,bubble-film");
  const rd::Image img = decode(r->body);
  json one = scene;
  one["bubbles"].erase(1);
  EXPECT_NE(decode(render(s, one)->body).rgba, img.rgba) << "the second bubble is drawn";
  auto answer = s.postJson("/v1/scene", scene);
  ASSERT_EQ(answer->status, 200) << answer->body;
  const json j = json::parse(answer->body);
  ASSERT_EQ(j["bubbles"].size(), 2u);
  EXPECT_EQ(j["bubbles"][1]["method"], "thin-film");
  json bad = scene;
  bad["bubbles"][1]["bubble"]["params"] = {{"wobbleAmplitude", 0.4}};  // x 3 rad per radius > 0.5
  EXPECT_TRUE(hasPointer(expectProblem(render(s, bad), 422), "/bubbles/1/bubble/params/wobbleAmplitude"));
  EXPECT_TRUE(hasPointer(expectProblem(s.postJson("/v1/scene", bad), 422), "/bubbles/1/bubble/params/wobbleAmplitude"));
}

TEST(Render, SceneReturnsEachPresentEffectAndNothingElse) {
  TestServer s;
  json scene = {{"fog", {{"fog", {{"fogType", "GL_EXP"}, {"density", 0.1}}}}},
                {"quads", {{{"center", {0, 0, 0}}, {"size", {1, 1}}}}}};
  auto r = s.postJson("/v1/scene", scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  json j = json::parse(r->body);
  EXPECT_EQ(j.size(), 1u) << r->body;
  EXPECT_TRUE(j["fog"].contains("table"));
  // A bolt's error figure is a header of its endpoint: the scene names it by the part's pointer.
  scene["lightning"] = {{"grid", {{"width", 32}, {"height", 32}}}, {"start", {16, 0}}, {"targets", {{16, 31}}}};
  auto b = s.postJson("/v1/scene", scene);
  ASSERT_EQ(b->status, 200) << b->body;
  EXPECT_EQ(b->get_header_value("X-Effect-Error").rfind("part=/lightning; meanTotalVariation=", 0), 0u)
      << b->get_header_value("X-Effect-Error");
}

// render/png.cpp against libpng (through OpenImageIO's reader, which checks every chunk's CRC
// and zlib the stream's Adler-32): 8-bit from bytes and from floats, 16-bit from floats, odd
// sizes, strips joined on one thread and on several; the same bytes either way.
TEST(Render, PngEncoderRoundTripsThroughLibpng) {
  effects::ThreadPool pool(3);
  uint64_t state = 7;
  auto next = [&state] { return (state = state * 6364136223846793005ULL + 1442695040888963407ULL) >> 33; };
  for (auto [w, h] : {std::pair{1, 1}, {3, 7}, {513, 300}, {1024, 97}}) {
    for (int bits : {8, 16}) {
      for (bool bytes : {false, true}) {
        if (bytes && bits == 16) continue;
        SCOPED_TRACE(std::to_string(w) + "x" + std::to_string(h) + " " + std::to_string(bits) +
                     (bytes ? " bits from bytes" : " bits from floats"));
        rd::Image img{w, h, {}, {}};
        const size_t n = size_t(w) * size_t(h) * 4;
        // Smooth ramps with noise in some rows, so that every filter wins somewhere.
        for (size_t i = 0; i < n; ++i) {
          const size_t x = (i / 4) % size_t(w), y = i / 4 / size_t(w);
          const double v = y % 5 == 0 ? double(next() % 65536) / 65535 : double(x + 3 * y + i % 4) / double(w + 3 * h);
          if (bytes)
            img.rgba8.push_back(uint8_t(std::lround(std::min(v, 1.0) * 255)));
          else
            img.rgba.push_back(float(std::min(v, 1.0)));
        }
        auto one = rd::encodePng(img, bits), several = rd::encodePng(img, bits, &pool);
        ASSERT_TRUE(one.ok()) << one.error().message;
        ASSERT_TRUE(several.ok());
        EXPECT_EQ(one.value(), several.value()) << "the same bytes on one thread and on several";
        EXPECT_EQ(uint8_t(one.value()[24]), bits) << "IHDR bit depth";
        rd::Image back = decode(one.value());
        ASSERT_EQ(back.width, w);
        ASSERT_EQ(back.height, h);
        const float step = bits == 8 ? 255.0f : 65535.0f;  // floats round as the encoder rounds them
        size_t off = 0;
        for (size_t i = 0; i < n; ++i) off += std::lround(back.rgba[i] * step) != std::lround(img.at(i) * step);
        EXPECT_EQ(off, 0u) << "samples that did not come back";
      }
    }
  }
  rd::Image wrong{2, 2, {}, std::vector<uint8_t>(16)};
  EXPECT_FALSE(rd::encodePng(wrong, 16).ok()) << "8-bit frames are not widened";
  wrong.rgba8.resize(15);
  EXPECT_FALSE(rd::encodePng(wrong, 8).ok()) << "too few values";
}

TEST(Render, SixteenBitPngKeepsTheGradient) {
  TestServer s;
  json scene = {{"width", 8},
                {"height", 256},
                {"bitDepth", 16},
                {"background", {{"gradient", {{"top", {1, 1, 1}}, {"bottom", {0, 0, 0}}}}}}};
  auto r = render(s, scene);
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  ASSERT_GT(r->body.size(), 25u);
  EXPECT_EQ(uint8_t(r->body[24]), 16) << "IHDR bit depth";
  rd::Image img = decode(r->body);
  EXPECT_GT(pixel(img, 0, 0).r, 0.99f) << "row 0 is the top";
  EXPECT_LT(pixel(img, 0, 255).r, 0.01f);
  // Adjacent rows differ by 1/256: an 8-bit detour would show steps of 0 or 2/255.
  for (int y = 1; y < 256; ++y) EXPECT_NEAR(pixel(img, 0, y - 1).r - pixel(img, 0, y).r, 1.0 / 256, 0.6 / 256);
}

TEST(Render, ConcurrentRendersAreCorrectAndThePoolStaysWithinItsSize) {
  rd::RenderPool pool({2, 64, ""});
  ASSERT_EQ(pool.start(), "");
  rd::Scene scene;
  scene.width = scene.height = 96;
  scene.quads.push_back({});
  scene.lightning = rd::Lightning{};
  scene.lightning->gridWidth = scene.lightning->gridHeight = 8;
  effects::lightning::Polyline line;
  line.main = true;
  line.width = 2;
  line.vertices = {{0.5f, 0.5f, 0.0f, 0, 1.0f, 0}, {7.5f, 7.5f, 0.0f, 1, 1.0f, 1}};
  scene.lightning->polylines = {line};
  std::vector<std::future<effects::Result<rd::Frame>>> jobs;
  std::vector<std::thread> clients;
  std::mutex mu;
  for (int c = 0; c < 8; ++c)
    clients.emplace_back([&] {
      for (int i = 0; i < 4; ++i) {
        auto f = pool.submit(scene);
        ASSERT_TRUE(f.has_value());
        std::lock_guard<std::mutex> lock(mu);
        jobs.push_back(std::move(*f));
      }
    });
  for (auto& t : clients) t.join();
  std::optional<rd::Image> first;
  for (auto& j : jobs) {
    auto frame = j.get();
    ASSERT_TRUE(frame.ok()) << frame.error().message;
    const rd::Image& image = frame.value().image;
    ASSERT_GT(image.values(), 0u);
    if (!first) first = image;
    EXPECT_EQ(image.rgba, first->rgba) << "same scene, same pixels on every thread";
    EXPECT_EQ(image.rgba8, first->rgba8) << "same scene, same pixels on every thread";
  }
  EXPECT_GE(pool.peakBusy(), 1);
  EXPECT_LE(pool.peakBusy(), 2);
}

TEST(Render, SaturatedPoolAnswers503WithRetryAfterAndRecovers) {
  Config c = TestServer::quietConfig();
  c.threads = 16;
  c.renderThreads = 1;
  c.renderQueue = 0;
  c.responseCacheMb = 0;  // repeats would be answered from the cache, never reaching the pool
  TestServer s(c);
  json scene = {{"width", 512},
                {"height", 512},
                {"lightning", {{"grid", {{"width", 64}, {"height", 64}}}, {"start", {32, 0}}, {"targets", {{32, 63}}}}},
                {"lightningStyle", {{"glowSigma", 20}}}};
  ASSERT_EQ(render(s, scene)->status, 200);  // the context exists before the burst
  std::vector<std::future<int>> burst;
  for (int i = 0; i < 8; ++i)
    burst.push_back(std::async(std::launch::async, [&] {
      auto r = render(s, scene);
      if (r && r->status == 503) {
        EXPECT_EQ(r->get_header_value("Retry-After"), "1");
      }
      return r ? r->status : 0;
    }));
  int ok = 0, busy = 0;
  for (auto& f : burst) {
    int st = f.get();
    ok += st == 200;
    busy += st == 503;
  }
  EXPECT_EQ(ok + busy, 8);
  EXPECT_GE(ok, 1);
  EXPECT_GE(busy, 1) << "one thread, no queue: concurrent renders beyond it are refused";
  EXPECT_EQ(render(s, scene)->status, 200) << "recovers once the burst is over";
}

TEST(Render, BadScenesNameTheField) {
  Config c = TestServer::quietConfig();
  c.limits.maxRenderPixels = 1000 * 1000;
  TestServer s(c);
  auto problem = [&](const json& scene, int status, const std::string& pointer) {
    auto r = render(s, scene);
    json p = expectProblem(r, status);
    EXPECT_TRUE(hasPointer(p, pointer)) << scene.dump().substr(0, 200) << " -> " << (r ? r->body : "");
  };
  problem({{"width", 2000}, {"height", 2000}}, 413, "/width");
  problem({{"width", 0}}, 400, "/width");
  problem({{"camera", {{"position", {1, 1, 1}}, {"target", {1, 1, 1}}}}}, 400, "/camera/target");
  problem({{"camera", {{"position", {0, 5, 0}}, {"target", {0, 0, 0}}}}}, 400, "/camera/up");
  problem({{"background", {{"image", "not base64!"}}}}, 400, "/background/image");
  problem({{"background", {{"image", base64Encode("GIF89a....")}}}}, 400, "/background/image");
  problem({{"background", {{"image", base64Encode(std::string("\x89PNG\r\n\x1a\n", 8) + "truncated")}}}}, 400,
          "/background/image");
  problem({{"background", {{"color", {0, 0, 0}}, {"gradient", {{"top", {0, 0, 0}}, {"bottom", {1, 1, 1}}}}}}}, 400,
          "/background");
  problem({{"lightning", {{"grid", {{"width", 8}, {"height", 8}}}, {"start", {9, 0}}, {"targets", {{1, 7}}}}}}, 400,
          "/lightning/start");
  problem({{"fog", {{"fog", {{"fogType", "GL_LINEAR"}, {"start", 5}, {"end", 1}}}}}}, 400, "/fog/fog/end");
  problem({{"bubble", {{"mesh", {{"level", 9}}}}}}, 400, "/bubble/mesh/level");
  problem({{"quads", {{{"center", {0, 0, 0}}, {"size", {1, 1}}, {"normal", {0, 0, 0}}}}}}, 400, "/quads/0/normal");
  problem({{"quads", {{{"center", {0, 0, -5}}, {"size", {1, 1}}}}}, {"surfaceWave", {{"quad", 1}}}}, 422,
          "/surfaceWave/quad");

  // A PNG larger than the pixel limit is refused from its header, before decoding.
  rd::Image big{1100, 1000, std::vector<float>(size_t(1100) * 1000 * 4, 0.5f)};
  auto png = rd::encodePng(big, 8);
  ASSERT_TRUE(png.ok());
  problem({{"background", {{"image", base64Encode(png.value())}}}}, 413, "/background/image");
}

// surfaceWave.quad puts the ripples on that quad in the world (water below the horizon): every
// pixel the waves change lies on the quad, none in the sky above it or on a wall in front of it.
TEST(Render, SurfaceWaveOnAQuadLightsOnlyThatQuad) {
  TestServer s;
  const json water = {{"center", {0, -1, -10}},
                      {"normal", {0, 1, 0}},
                      {"up", {0, 0, -1}},
                      {"size", {40, 30}},
                      {"color", {0.1, 0.12, 0.18}}};
  const json wall = {{"center", {0, -0.5, -4}}, {"size", {1, 1.5}}, {"color", {0.3, 0.3, 0.3}}};
  json scene = {{"width", 96},
                {"height", 96},
                {"time", 5},
                {"camera", {{"position", {0, 1, 6}}, {"target", {0, 0.5, 0}}, {"fovY", 50}}},
                {"background", {{"color", {0.05, 0.05, 0.1}}}},
                {"quads", {water, wall}}};
  const rd::Image plain = decode(render(s, scene)->body);
  scene["surfaceWave"] = {{"strength", 2}, {"scale", 4}, {"quad", 0}};
  auto r = render(s, scene);
  ASSERT_EQ(r->status, 200) << r->body;
  EXPECT_NE(r->get_header_value("X-Render-Passes").find("surfaceWave:quad"), std::string::npos);
  const rd::Image waves = decode(r->body);
  // Which pixels show the water, the wall, the sky: the same scene with each quad recoloured.
  json marked = scene;
  marked.erase("surfaceWave");
  marked["background"] = {{"color", {0, 0, 0}}};
  marked["quads"][0]["color"] = {1, 0, 0};
  marked["quads"][1]["color"] = {0, 1, 0};
  const rd::Image mask = decode(render(s, marked)->body);
  size_t onWater = 0, elsewhere = 0;
  for (int y = 0; y < 96; ++y)
    for (int x = 0; x < 96; ++x) {
      const bool changed = glm::length(glm::vec3(pixel(waves, x, y) - pixel(plain, x, y))) > 2.0f / 255;
      const glm::vec4 m = pixel(mask, x, y);
      if (changed) (m.r > 0.5f && m.g < 0.5f ? onWater : elsewhere)++;
    }
  EXPECT_GT(onWater, 300u);
  EXPECT_EQ(elsewhere, 0u) << "waves outside the water quad";
}

json strikeScene(int frames, const char* format) {
  return {{"width", 96},
          {"height", 96},
          {"frames", {{"count", frames}, {"fps", 20}, {"format", format}}},
          {"lightning",
           {{"grid", {{"width", 48}, {"height", 48}}}, {"start", {24, 0}}, {"targets", {{24, 47}}}, {"timeScale", 4}}}};
}

// An animated render's answer: 200, its media type and frame count.
httplib::Result renderFrames(const TestServer& s, const json& scene, const std::string& type) {
  auto r = render(s, scene);
  EXPECT_TRUE(r && r->status == 200) << (r ? r->body.substr(0, 300) : "");
  if (!r || r->status != 200) return r;
  EXPECT_EQ(r->get_header_value("Content-Type"), type);
  EXPECT_EQ(r->get_header_value("X-Frame-Count"), std::to_string(scene["frames"]["count"].get<int>()));
  return r;
}

// render/gif.cpp against giflib (OpenImageIO's GIF reader): every frame comes back at its size;
// a frame of at most 255 colours exactly; a frame of many colours within a few levels; pixels
// of alpha < 1/2 transparent; delta frames (pixels unchanged from the frame before left
// transparent) show the whole frame; one thread or several, the same bytes.
TEST(Render, GifEncoderRoundTripsThroughGiflib) {
  const int w = 37, h = 23, count = 11;
  std::vector<rd::Image> frames;
  uint64_t state = 3;
  auto next = [&state] { return (state = state * 6364136223846793005ULL + 1442695040888963407ULL) >> 33; };
  for (int f = 0; f < count; ++f) {
    rd::Image img{w, h, {}, std::vector<uint8_t>(size_t(w) * h * 4)};
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x) {
        uint8_t* p = &img.rgba8[(size_t(y) * w + x) * 4];
        if (f % 3 == 0) {  // a few colours, moving
          const int k = (x / 5 + y / 4 + f) % 40;
          p[0] = uint8_t(k * 6), p[1] = uint8_t(255 - k * 5), p[2] = uint8_t(k * 3 + 7), p[3] = 255;
        } else if (f % 3 == 1) {  // thousands of colours
          p[0] = uint8_t(next()), p[1] = uint8_t(x * 7), p[2] = uint8_t(y * 11), p[3] = 255;
        } else {  // the frame before, one corner changed, and a transparent hole
          std::copy_n(&frames.back().rgba8[(size_t(y) * w + x) * 4], 4, p);
          if (x < 6 && y < 6) p[0] = uint8_t(255 - p[0]);
          if (x > 30 && y > 15) p[3] = 0;
        }
      }
    frames.push_back(std::move(img));
  }
  effects::ThreadPool pool(3);
  std::string bytes[2];
  for (int run = 0; run < 2; ++run) {
    rd::GifEncoder gif(w, h, count, 10, run ? &pool : nullptr);
    for (const rd::Image& f : frames) ASSERT_FALSE(gif.add(f).has_value());
    auto out = gif.finish();
    ASSERT_TRUE(out.ok()) << out.error().message;
    bytes[run] = out.value();
  }
  EXPECT_EQ(bytes[0], bytes[1]) << "the same bytes on one thread and on several";
  const std::vector<rd::Image> back = decodeGif(bytes[0]);
  ASSERT_EQ(back.size(), size_t(count));
  for (int f = 0; f < count; ++f) {
    SCOPED_TRACE("frame " + std::to_string(f));
    ASSERT_EQ(back[size_t(f)].width, w);
    ASSERT_EQ(back[size_t(f)].height, h);
    double sum = 0, worst = 0;
    size_t holes = 0;
    for (size_t i = 0; i < size_t(w) * h; ++i) {
      const uint8_t* want = &frames[size_t(f)].rgba8[i * 4];
      const float* got = &back[size_t(f)].rgba[i * 4];
      if (want[3] < 128) {
        holes += got[3] < 0.5f;
        continue;
      }
      for (int c = 0; c < 3; ++c) {
        const double d = std::abs(double(got[c]) * 255 - want[c]);
        sum += d, worst = std::max(worst, d);
      }
    }
    if (f % 3 == 0) EXPECT_LT(worst, 0.51) << "at most 255 colours come back exactly";
    // Random reds over gradients: 255 cells of a 256-level cube are ~40 levels a side.
    if (f % 3 == 1) EXPECT_LT(sum / (w * h * 3), 12.0) << "mean error in levels of 255";
    if (f % 3 == 2) EXPECT_EQ(holes, size_t(6 * 7)) << "the transparent hole";
  }
  rd::GifEncoder short_(w, h, 2, 10);
  ASSERT_FALSE(short_.add(frames[0]).has_value());
  EXPECT_FALSE(short_.finish().ok()) << "fewer frames than announced";
  EXPECT_TRUE(short_.add(rd::Image{w + 1, h, {}, std::vector<uint8_t>(size_t(w + 1) * h * 4)}).has_value())
      << "a frame of another size";
}

TEST(Render, StrikeAsAnimatedGif) {
  TestServer s;
  auto r = renderFrames(s, strikeScene(30, "gif"), "image/gif");
  ASSERT_TRUE(r && r->status == 200);
  const std::vector<rd::Image> g = decodeGif(r->body);
  ASSERT_EQ(g.size(), 30u);
  EXPECT_EQ(g[0].width, 96);
  EXPECT_EQ(g[0].height, 96);
  // The strike lights the first frames, strokes re-light it, the last frames are dark again.
  std::vector<double> brightness;
  for (const auto& f : g) brightness.push_back(meanBrightness(f));
  EXPECT_GT(brightness[0], brightness.back() + 0.01);
  EXPECT_LT(std::abs(brightness[29] - brightness[28]), 1e-3);
  int relit = 0;
  for (size_t i = 1; i < brightness.size(); ++i) relit += brightness[i] > brightness[i - 1] + 0.002;
  EXPECT_GE(relit, 2) << "re-strikes";
  // The same scene, the same bytes; another animation seed, another movie of the same bolt.
  EXPECT_EQ(render(s, strikeScene(30, "gif"))->body, r->body);
  json other = strikeScene(30, "gif");
  other["lightning"]["animationSeed"] = 9;
  EXPECT_NE(render(s, other)->body, r->body);
}

TEST(Render, FlipbookHoldsTheFramesInAGrid) {
  TestServer s;
  auto r = renderFrames(s, strikeScene(10, "flipbook"), "image/png");
  ASSERT_TRUE(r && r->status == 200);
  EXPECT_EQ(r->get_header_value("X-Flipbook-Columns"), "4");
  EXPECT_EQ(r->get_header_value("X-Flipbook-Rows"), "3");
  const rd::Image sheet = decode(r->body);
  EXPECT_EQ(sheet.width, 4 * 96);
  EXPECT_EQ(sheet.height, 3 * 96);
  EXPECT_EQ(pixel(sheet, 3 * 96 + 50, 2 * 96 + 50).a, 0.0f);  // after the last frame: empty
  EXPECT_EQ(pixel(sheet, 50, 50).a, 1.0f);

  // A wobbling bubble reflecting a sky: frames differ.
  json bubble = {{"width", 64},
                 {"height", 64},
                 {"frames", {{"count", 4}, {"fps", 4}, {"format", "flipbook"}}},
                 {"environment", json::object()},
                 {"bubble", json::object()}};
  r = renderFrames(s, bubble, "image/png");
  ASSERT_TRUE(r && r->status == 200);
  const rd::Image b = decode(r->body);
  double diff = 0;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) diff += glm::length(pixel(b, x, y) - pixel(b, 64 + x, y));
  EXPECT_GT(diff, 1.0);
}

TEST(Render, FramesAreBoundedByThePixelLimit) {
  Config c = TestServer::quietConfig();
  c.limits.maxRenderPixels = 96 * 96 * 20;
  TestServer s(c);
  json p = expectProblem(render(s, strikeScene(21, "gif")), 413);
  EXPECT_TRUE(hasPointer(p, "/frames/count")) << p.dump();
  EXPECT_EQ(render(s, strikeScene(20, "gif"))->status, 200);
  p = expectProblem(render(s, {{"frames", {{"count", 0}}}}), 400);
  EXPECT_TRUE(hasPointer(p, "/frames/count")) << p.dump();
  // A flipbook's unused cells count: 18 frames make a 5 x 4 sheet, 20 frames' worth of pixels.
  EXPECT_EQ(render(s, strikeScene(18, "gif"))->status, 200);
  EXPECT_EQ(render(s, strikeScene(16, "flipbook"))->status, 200);  // 4 x 4
  c.limits.maxRenderPixels = 96 * 96 * 19;
  TestServer tight(c);
  EXPECT_EQ(tight.postJson("/v1/render", strikeScene(18, "gif"))->status, 200);
  p = expectProblem(tight.postJson("/v1/render", strikeScene(18, "flipbook")), 413);
  EXPECT_TRUE(hasPointer(p, "/frames/count")) << p.dump();
}

TEST(Render, BackgroundImageFillsTheFrame) {
  TestServer s;
  rd::Image img{2, 2, {1, 0, 0, 1, 0, 1, 0, 1, 0, 0, 1, 1, 1, 1, 1, 1}};  // red green / blue white
  auto png = rd::encodePng(img, 8);
  ASSERT_TRUE(png.ok());
  auto r = render(s, {{"width", 64}, {"height", 64}, {"background", {{"image", base64Encode(png.value())}}}});
  ASSERT_TRUE(r);
  ASSERT_EQ(r->status, 200) << r->body;
  rd::Image out = decode(r->body);
  EXPECT_GT(pixel(out, 2, 2).r, 0.95f);   // top left red
  EXPECT_GT(pixel(out, 61, 2).g, 0.95f);  // top right green
  EXPECT_GT(pixel(out, 2, 61).b, 0.95f);  // bottom left blue
  EXPECT_GT(pixel(out, 61, 61).r + pixel(out, 61, 61).g + pixel(out, 61, 61).b, 2.85f);
}


// A 3-D bolt seen through fog glows by the fog's APSF; without fog, today's Gaussian.
// The glow alone (the frame minus the same frame with glowStrength 0) spreads wider as the fog
// between the camera and the bolt thickens, and the header names the kernel that ran.
TEST(Render, BoltInFogGlowsByItsApsf) {
  TestServer s;
  json scene = json::parse(slurp(fs::path(EFFECTD_EXAMPLES_DIR) / "09-bolt-3d.json"));
  scene["width"] = scene["height"] = 256;
  scene["camera"]["fovY"] = 90;
  scene.erase("quads");
  scene["lightningStyle"]["forwardScattering"] = 0.99;
  auto render = [&](const json& body, std::string* glow = nullptr, std::string* passes = nullptr) {
    auto r = s.postJson("/v1/render", body.dump());
    EXPECT_TRUE(r && r->status == 200);
    if (!r || r->status != 200) return rd::Image{};
    if (glow) *glow = r->get_header_value("X-Glow");
    if (passes) *passes = r->get_header_value("X-Render-Passes");
    return decode(r->body);
  };
  {
    json clear = scene;
    clear.erase("fog");
    std::string glow, passes;
    render(clear, &glow, &passes);
    EXPECT_EQ(glow.rfind("gaussian sigma", 0), 0u) << glow;
    EXPECT_EQ(passes.find("glowApsf"), std::string::npos) << passes;
  }
  double previousT = 0, previousRadius = 0;
  for (double density : {0.055, 0.08, 0.14}) {
    json fogged = scene;
    fogged["fog"] = {{"fog", {{"fogType", "GL_EXP"}, {"color", {0, 0, 0}}, {"density", density}}}};
    std::string glow, passes;
    const rd::Image with = render(fogged, &glow, &passes);
    fogged["lightningStyle"]["glowStrength"] = 0;
    const rd::Image without = render(fogged);
    ASSERT_EQ(with.rgba.size(), without.rgba.size());
    EXPECT_NE(passes.find("glowApsf"), std::string::npos) << passes;
    ASSERT_EQ(glow.rfind("apsf T ", 0), 0u) << glow;
    const double t = std::stod(glow.substr(7));
    // The glow's light and its centre, then the radius holding half of it.
    std::vector<std::tuple<double, double, double>> light;  // x, y, amount
    double total = 0, cx = 0, cy = 0;
    for (int y = 0; y < with.height; ++y)
      for (int x = 0; x < with.width; ++x) {
        const size_t i = 4 * (size_t(y) * size_t(with.width) + size_t(x));
        const double a = std::max(0.0, double(with.at(i) - without.at(i)));
        light.emplace_back(x, y, a);
        total += a, cx += a * x, cy += a * y;
      }
    ASSERT_GT(total, 1.0) << "no glow at density " << density;
    cx /= total, cy /= total;
    std::vector<std::pair<double, double>> byDistance;
    for (auto [x, y, a] : light) byDistance.emplace_back(std::hypot(x - cx, y - cy), a);
    std::sort(byDistance.begin(), byDistance.end());
    double sum = 0, radius = 0;
    for (auto [d, a] : byDistance)
      if ((sum += a) >= total / 2) {
        radius = d;
        break;
      }
    EXPECT_GT(t, previousT) << glow;
    EXPECT_GT(radius, previousRadius) << "density " << density << ": " << glow;
    previousT = t, previousRadius = radius;
  }
}

// The core of a 3-D bolt in fog reaches the eye through it: under a GL_EXP fog dense enough to be
// complete within a hundredth of a unit but capped at maxOpacity 0.6, the closed form lets 0.4
// through at every vertex, so every lit pixel of the core (glow off) is 0.4 of its clear-air value.
TEST(Render, BoltCoreIsDimmedByItsFog) {
  TestServer s;
  json scene = json::parse(slurp(fs::path(EFFECTD_EXAMPLES_DIR) / "09-bolt-3d.json"));
  scene["width"] = scene["height"] = 256;
  scene.erase("quads");
  scene["background"] = {{"color", {0, 0, 0, 1}}};
  scene["lightningStyle"]["glowStrength"] = 0;
  scene.erase("fog");  // the example's own GL_EXP2
  auto render = [&](const json& body) {
    auto r = s.postJson("/v1/render", body.dump());
    EXPECT_TRUE(r && r->status == 200);
    return r && r->status == 200 ? decode(r->body) : rd::Image{};
  };
  const rd::Image clear = render(scene);
  scene["fog"] = {{"fog", {{"fogType", "GL_EXP"}, {"color", {0, 0, 0}}, {"density", 1000}, {"maxOpacity", 0.6}}}};
  const rd::Image fogged = render(scene);
  ASSERT_EQ(clear.rgba.size(), fogged.rgba.size());
  size_t lit = 0;
  double worst = 0;
  for (size_t i = 0; i < clear.values(); i += 4) {
    const double before = clear.at(i), after = fogged.at(i);  // red: 0.72 at the core, never saturated
    if (before < 100.0 / 255) continue;
    ++lit;
    worst = std::max(worst, std::abs(after - 0.4 * before));
  }
  EXPECT_GT(lit, 100u);
  EXPECT_LE(worst, 1.01 / 255) << "over " << lit << " lit pixels";
}

}  // namespace
}  // namespace effectd::testing
