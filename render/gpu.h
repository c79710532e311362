// What the passes share (internal to render/): the per-context GPU state (program cache,
// textures made once), the frame being drawn, and one function per pass. Each pass draws
// into the frame's main target (or its own targets), appends its name to Frame::passes, and
// returns an Error when the GPU refuses; renderer.cpp decides which passes a scene needs.
#pragma once

#include <array>

#include <deque>
#include <map>
#include <tuple>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <effects/tangents.h>

#include "gl.h"
#include "internal.h"

namespace effects::render::detail {

inline constexpr double kPi = 3.14159265358979323846;
inline constexpr int kEnvironmentSize = 256;  // cube map face of the bubble's environment
inline constexpr int kMaxBlurRadius = 64;     // taps each side in the glow blur

// Generated textures (textures.cpp).
std::vector<uint8_t> normalMap(int size, uint64_t seed);
std::vector<uint8_t> softPattern(int size, int channels, uint64_t seed, double lo, double hi);
std::vector<float> premultiplied(const Image& image);
inline glm::vec4 premultiplied(const glm::dvec4& c) { return glm::vec4(glm::dvec3(c) * c.a, c.a); }

// GPU copies of objects that scenes share (a thin-film table, a sphere mesh), found by the
// shared object they were made from, which they keep alive: a render thread keeps its last few.
template <class Source, class Object>
struct Uploads {
  static constexpr size_t kKept = 4;
  std::deque<std::pair<std::shared_ptr<const Source>, std::unique_ptr<Object>>> entries;
  // The object made from `source` (by make() the first time); the oldest goes past kKept.
  template <class Make>
  Object& get(const std::shared_ptr<const Source>& source, Make make) {
    for (auto& e : entries)
      if (e.first == source) return *e.second;
    if (entries.size() == kKept) entries.pop_front();
    entries.emplace_back(source, make());
    return *entries.back().second;
  }
};

struct Gpu {
  EglContext egl;
  std::string description;
  int maxTextureSize = 0;
  bool floatBlend = false;
  GLuint emptyVao = 0;
  std::map<std::string, Program> programs;
  int compiled = 0;  // programs compiled during the current frame
  Texture normalA, normalB, waveAlpha, defaultFlow;
  std::vector<float> waveVertices;  // the surface-wave quad with its MikkTSpace frames
  std::vector<uint32_t> waveIndices;
  // Kept from frame to frame (made again only when a frame's size or format differs): the
  // frame, its 8-bit resolve, the bolt's core and glow buffers, the environment cube.
  Target main, resolved, boltCore, blurred, glow;
  Target apsfBlurred[3], apsfGlow[3];  // the APSF glow's Gaussians, each at its own resolution
  // Fitted APSF kernels by (T, q, method): an animation's frames share one.
  std::map<std::tuple<double, double, int>, glow::Kernel> apsfKernels;
  Texture environment;
  GLuint environmentFbo = 0;
  Uploads<bubble::ThinFilmTable, Texture> thinFilms;
  Uploads<bubble::Mesh, Vertices> spheres;  // position, normal, uv

  ~Gpu();
  // The program for `key` (compiled and linked on first use: the variant cache); source()
  // gives its (vertex, fragment) GLSL and is called only then.
  template <class Source>
  Result<Program*> program(const std::string& key, Source source) {
    if (auto it = programs.find(key); it != programs.end()) return &it->second;
    const auto [vs, fs] = source();
    return compileProgram(key, vs, fs);
  }
  Result<Program*> compileProgram(const std::string& key, const std::string& vs, const std::string& fs);
  // The bubble's flow texture: its own image (uploaded into `owned`) or the default pattern.
  const Texture& flowTexture(const Bubble& b, Texture& owned);
  // Generated once per context: the two normal maps, the alpha texture, and the quad with
  // its MikkTSpace frames (seed 004's TBN for the ripple lighting).
  std::optional<Error> ensureWave();
};

struct View {
  glm::mat4 view, projection, viewProjection;
  glm::vec2 tanHalfFov;
  glm::vec3 eye;
};

// Camera matrices of the scene.
View viewOf(const Scene& s);

// One frame in progress.
struct FrameState {
  const Scene& scene;
  View view;
  Target& main;                   // premultiplied RGBA float with depth (Gpu::main)
  std::optional<fog::ShaderVariant> fog;  // the fog shader variant when the scene has fog
  std::string fogKey;             // ":" + its key, part of the program keys that include fog
  Texture backgroundImage;        // the backdrop image, when it is one
  Frame frame;
};

// Backdrop uniforms of a background or environment program (passes/background.cpp).
void setBackground(Program& p, const Background& b, const Texture* image);

// A quad's corners as it is drawn: centre -/+ right -/+ up, counter-clockwise seen from its
// normal's side (passes/quads.cpp).
std::array<glm::dvec3, 4> quadCorners(const Quad& q);

std::optional<Error> backgroundPass(Gpu& gpu, FrameState& f);   // passes/background.cpp
std::optional<Error> surfaceWavePass(Gpu& gpu, FrameState& f);  // passes/surface_wave.cpp
std::optional<Error> quadsPass(Gpu& gpu, FrameState& f);        // passes/quads.cpp
std::optional<Error> bubblePass(Gpu& gpu, FrameState& f);       // passes/bubble.cpp
std::optional<Error> lightningPass(Gpu& gpu, FrameState& f);    // passes/lightning.cpp
std::optional<Error> cameraBlendPass(Gpu& gpu, FrameState& f);  // passes/camera_blend.cpp

}  // namespace effects::render::detail
