// render/render.h — headless previews of effectd scenes through EGL + OpenGL ES 3.
//
// A Scene holds the effect data the effects library computed (lightning polylines, fog
// definitions, the bubble's mesh and parameters) plus a camera and a background. Passes are
// built only for what the scene contains, from shader variants composed per feature set and
// cached per context: a scene without lightning runs no blur pass, a scene without fog has
// no fog code in any shader. Frame::passes and Frame::variantsCompiled say what ran.
//
// Colours are written as given (no sRGB transfer is applied): the fog colours in a render
// are the numbers /v1/fog's tables give. Internally colours are premultiplied by alpha; the
// output is straight alpha, rows top to bottom.
//
// Contexts: EGL_EXT_platform_device is preferred (it lists GPUs when there are any); Mesa's
// surfaceless platform is the fallback (llvmpipe on machines without a GPU). The environment
// variable EFFECTD_EGL_PLATFORM=device|surfaceless forces one. A Renderer's context is bound
// to the thread that created it; RenderPool owns one Renderer per worker thread.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <future>
#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <glm/vec2.hpp>
#include <glm/vec3.hpp>
#include <glm/vec4.hpp>

#include <effects/bubble.h>
#include <effects/common.h>
#include <effects/fog.h>
#include <effects/glow.h>
#include <effects/lightning.h>
#include <effects/parallel.h>

namespace effects::render {

// Straight-alpha RGBA, rows top to bottom: floats in [0, 1], or (a frame read back for an
// 8-bit PNG) bytes, value round(255 x) — one of the two is filled.
struct Image {
  int width = 0, height = 0;
  std::vector<float> rgba;
  std::vector<uint8_t> rgba8;
  size_t values() const { return rgba8.empty() ? rgba.size() : rgba8.size(); }
  float at(size_t i) const { return rgba8.empty() ? rgba[i] : float(rgba8[i]) / 255.0f; }
};
// The image's 8-bit values: its bytes, or its floats rounded to round(255 x) (an 8-bit PNG's
// and a GIF's samples).
std::vector<uint8_t> bytes8(const Image& image);

struct Camera {
  glm::dvec3 position{0, 1, 6}, target{0, 0.5, 0}, up{0, 1, 0};
  double fovYDeg = 45, nearPlane = 0.05, farPlane = 1000;
};

// The backdrop as a function of view direction: a direction in front of the camera maps to
// the screen point it projects to, one behind it to the mirror image. So the image fills the
// screen exactly, and the bubble's environment lookups see the same backdrop.
struct Background {
  enum class Kind { kColor, kGradient, kImage } kind = Kind::kColor;
  glm::dvec4 color{0.02, 0.03, 0.05, 1};
  glm::dvec4 top{0.25, 0.45, 0.8, 1}, bottom{0.85, 0.9, 0.95, 1};  // gradient, screen top -> bottom
  Image image;
};

// What reflections see when the scene gives it: a sky in world directions (y up), zenith to
// horizon to ground, instead of the backdrop (the screen's picture, mirrored behind the
// camera). Games reflect a sky box; the backdrop is what lies behind the bubble.
struct Environment {
  glm::dvec3 zenith{0.25, 0.5, 0.95}, horizon{0.9, 0.93, 1.0}, ground{0.25, 0.22, 0.2};
};
// The sky in direction d (unit): y >= 0 mix(horizon, zenith, sqrt(y)), below mix(horizon,
// ground, sqrt(min(-4 y, 1))); the environment pass evaluates the same in GLSL
// (environmentFragment).
glm::dvec3 skyAt(const Environment& e, const glm::dvec3& d);

// Seed 000 section 2.2: a quad in front of the backdrop with two normal maps scrolling in
// different directions, lit through the quad's MikkTSpace TBN frame (seed 004), and an alpha
// texture: "sunlight under water".
struct SurfaceWave {
  double strength = 0.35;  // brightness of the ripple highlights
  double scale = 3;        // normal-map repeats across the quad
  double speed = 0.03;     // uv units per second
  glm::dvec3 lightColor{1.0, 0.97, 0.85};
  glm::dvec3 lightDirection{0.2, 0.6, 1.0};  // in the quad's tangent space, towards the light
  // The waves on Scene::quads[*onQuad] in the world (water): its corners, depth-tested and
  // fogged with it; without it, a quad over the whole frame on the backdrop (seed 000 §2.2).
  std::optional<size_t> onQuad;
};

// Seed 000 eqn 12: renderTex = lerp(renderTex, blend, epsilon), last pass over the frame.
struct CameraBlend {
  glm::dvec3 color{0, 0, 0};
  double amount = 0;  // epsilon in [0, 1]
};

// An opaque rectangle in the world (a wall, a floor): geometry for fog to act on.
struct Quad {
  glm::dvec3 center{0, 0, 0}, normal{0, 0, 1}, up{0, 1, 0};
  glm::dvec2 size{1, 1};
  glm::dvec3 color{0.5, 0.5, 0.5};
};

// Seed 002 section 3.3: the bolt into its own framebuffer (main channel twice as wide,
// branches dimmer), a separable Gaussian blur (horizontal, then vertical), added over the scene.
// The grid maps onto `rect` = (x0, y0, x1, y1) in image fractions, y down like the grid.
struct Lightning {
  std::vector<lightning::Polyline> polylines;
  int gridWidth = 0, gridHeight = 0;
  glm::dvec4 rect{0, 0, 1, 1};
  // A 3-D bolt: vertices are world positions (x, y, z), drawn through the scene's camera as
  // camera-facing ribbons, depth-tested against the scene; coreWidth is then the width in
  // pixels where the bolt's middle lies, wider nearer the camera and narrower farther. rect
  // and the grid size do not apply.
  bool world = false;
  glm::dvec3 color{0.75, 0.85, 1.0};
  double coreWidth = 1.5;  // pixels per unit of polyline width (main 2, branch 1)
  double glowSigma = 6;    // Gaussian sigma in pixels; 0 = no glow (no blur pass)
  double glowStrength = 1.5;
  // A 3-D bolt in a scene with fog is seen through it (docs/rendering.md "The bolt in fog"):
  // each vertex dimmed by the fog's transmittance along its ray, and the glow, instead of the
  // Gaussian, the atmospheric point spread function (effects/glow.h) of the fog between the
  // camera and the bolt's middle: glowStrength x radiance x (1 - e^-T) x the kernel, drawn as
  // its fitted Gaussians. radiance is the core's brightness in display units (lightning is far
  // brighter than what a display shows, and the halo is that light spread over tens of degrees).
  double radiance = 100;
  std::optional<double> forwardScattering;  // q; none: the fog's own (glow::forwardScatteringOf)
  glow::Method apsfMethod = glow::Method::kGaussians3;  // kGaussian, kGaussians2 or kGaussians3
};

struct Fog {
  fog::Fog global;
  std::vector<fog::Region> regions;  // at most kMaxFogRegions
};
inline constexpr size_t kMaxFogRegions = 16;


// The bubble with effectd's shader (bubble::shader) for `features` (the soap film, or seed
// 000's model); wobble runs in the vertex shader, so the mesh is the undisturbed icosphere of
// `radius` around `center`.
struct Bubble {
  bubble::Params params;
  bubble::Features features;
  std::shared_ptr<const bubble::Mesh> mesh;  // shared by the scenes that use the same sphere
  glm::dvec3 center{0, 0, 0};
  double time = 0;  // seconds (eqns 3, 9, 11)
  glm::dvec4 baseColor = bubble::kBaseColor;
  double radius = 1;  // of the mesh, object units (the wobble's unit)
  std::shared_ptr<const bubble::ThinFilmTable> thinFilm;  // film model, or iridescence (shared)
  glm::dvec2 thinFilmRangeNm{0, 1000};  // thickness at the table's first and last column
  bubble::ThicknessOptions film;        // film model: the thickness field, computed per frame at `time`
  // The field, when the scene's builder computed it off the render thread (prepareThickness),
  // at thicknessTime; a frame at another time (an animation's) has the render thread compute it.
  std::optional<bubble::ThicknessField> thickness;
  double thicknessTime = 0;
  std::vector<bubble::Light> lights;    // film model with features.highlight, at most kMaxLights
  Image flowTexture;  // eqn 9's texture; empty = a generated soft swirl
};

struct Scene {
  int width = 512, height = 512;
  int bitDepth = 8;  // PNG bits per channel: 8 or 16
  double time = 0;
  Camera camera;
  Background background;
  std::optional<Environment> environment;  // reflections: this sky, else the backdrop
  std::optional<SurfaceWave> wave;
  std::vector<Quad> quads;
  std::optional<Fog> fog;
  std::vector<Bubble> bubbles;  // drawn far to near
  std::optional<Lightning> lightning;
  std::optional<CameraBlend> blend;
};

struct Frame {
  Image image;
  std::vector<std::string> passes;  // in the order they ran
  int variantsCompiled = 0;         // shader programs compiled for this frame (0 when all cached)
  int variantsCached = 0;           // programs in this context's cache afterwards
  double ms = 0;                    // GPU work including read-back (a sequence: each frame's
                                    // preparation too)
  double drawMs = 0;                // the passes issued and finished (glFinish), + preparation
  double readMs = 0;                // the pixels read back and converted
  double queueMs = 0;               // waiting for a render thread, before ms
  std::string glow;                 // which glow the bolt got, e.g. "gaussian sigma 6 px" or
                                    // "apsf T 2.1 q 0.9 gaussians-3 (misplaced 0.0005)"; "" without a bolt
  std::string passList() const;     // "background,quads,...": the passes, comma-separated
};

// Renders several frames of one scene in one job: before frame i, prepare(scene, i) moves the
// scene on (time, animated parts); after it, consume(frame, i) takes the pixels.
struct Sequence {
  int count = 1;
  std::function<void(Scene&, int)> prepare;
  std::function<std::optional<Error>(const Frame&, int)> consume;
};

// Which EGL platform to use: "auto" (device, then surfaceless), "device" or "surfaceless".
// Empty = the EFFECTD_EGL_PLATFORM environment variable, else "auto".
class Renderer {
 public:
  static Result<std::unique_ptr<Renderer>> create(const std::string& platform = "");
  ~Renderer();
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  // Call on the creating thread only.
  Result<Frame> render(const Scene& scene);
  Result<Frame> render(Scene& scene, const Sequence& sequence);
  // e.g. "llvmpipe (LLVM 15.0.6, 256 bits) via surfaceless"
  const std::string& description() const;

 private:
  Renderer();
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A physical reference of the scene's bubble, ray traced on the CPU (reference.cpp): the
// analytic sphere (the wobble must be off), the backdrop as the renderer sees it, and the film
// per wavelength (400, 1 nm: Airy for s and p, at the exact traced thickness of each point):
// the front film's reflection, the light through both films, and the far film's reflection
// seen back through the near one; lights as in the film shader. What the shading variants are
// measured against (docs/rendering.md, docs/error-vs-time.md). A scene with anything but a backdrop and a
// bubble is refused (kUnsatisfiable naming the field).
struct Reference {
  Image image;                 // opaque, straight alpha
  std::vector<uint8_t> bubble;  // per pixel: 1 where the ray meets the bubble
  double ms = 0;
};
inline constexpr int kReferenceWavelengths = 400;
Result<Reference> referenceRender(const Scene& scene, Parallel* parallel = nullptr);
// CIE76 Delta E*ab of a frame against the reference, per pixel where the reference's ray meets
// the bubble (in pixel order), the frame as it holds its values (an 8-bit frame: its bytes).
std::vector<double> bubbleDeltaE(const Image& frame, const Reference& reference);

// The film's thickness field at b.time as a frame draws it; prepareThickness stores it in b
// (film model with the thickness feature; nothing otherwise).
Result<bubble::ThicknessField> thicknessOf(const Bubble& b, Parallel* parallel);
std::optional<Error> prepareThickness(Bubble& b, Parallel* parallel);

// PNG bytes of `image` (8 or 16 bits per channel, RGBA, straight alpha); its strips are
// filtered and deflated on `parallel` (null: this thread only), the same bytes either way.
Result<std::string> encodePng(const Image& image, int bitDepth, Parallel* parallel = nullptr);

// An animated GIF (gif.cpp; 255 colours and a transparent index per frame, looping forever),
// frames encoded in batches of 8 on `parallel` (null: the calling thread only), so a sequence
// holds at most 9 frames. GIF delays are whole hundredths of a second, at least 2 (browsers
// play shorter ones at 10 fps): a frame lasts gifDelay(fps) hundredths, so the rate played is
// 100 / gifDelay(fps) (fps <= 50).
int gifDelay(double fps);
class GifEncoder {
 public:
  GifEncoder(int width, int height, int count, double fps, Parallel* parallel = nullptr);
  ~GifEncoder();
  GifEncoder(const GifEncoder&) = delete;
  GifEncoder& operator=(const GifEncoder&) = delete;
  std::optional<Error> add(const Image& frame);
  Result<std::string> finish();  // after `count` frames

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// A flipbook (sprite sheet): `count` frames in a grid, left to right, top to bottom, as the
// texture-sheet animations of engines play them (Unity's Texture Sheet Animation, Unreal's
// SubUV). columns = ceil(sqrt(count)), rows = ceil(count / columns); unused cells transparent.
// The sheet's size: Flipbook::cells(count) frames.
// The sheet's pixels are allocated by the first put().
struct Flipbook {
  int columns = 0, rows = 0, frameWidth = 0, frameHeight = 0;
  Image sheet;
  Flipbook(int width, int height, int count);
  static int cells(int count);  // columns * rows
  void put(const Image& frame, int index);
};

// Decodes PNG/JPEG/anything OpenImageIO reads from memory into straight-alpha RGBA float.
// Images with more than maxPixels pixels are refused before their pixels are decoded.
Result<Image> decodeImage(const std::string& bytes, size_t maxPixels);

// A fixed pool of render threads, one Renderer each, fed by a bounded queue.
struct PoolOptions {
  int threads = 2;
  int queue = 8;         // waiting jobs beyond the running ones
  std::string platform;  // as for Renderer::create
};

class RenderPool {
 public:
  explicit RenderPool(PoolOptions options);
  ~RenderPool();  // finishes queued jobs, joins the threads
  RenderPool(const RenderPool&) = delete;
  RenderPool& operator=(const RenderPool&) = delete;

  // nullopt when the queue is full (the caller answers 503 + Retry-After).
  std::optional<std::future<Result<Frame>>> submit(Scene scene);
  // A frame sequence as one job; the Frame returned has no pixels (consume took them), the
  // last frame's passes, and the compile counts and times summed over the frames.
  std::optional<std::future<Result<Frame>>> submit(Scene scene, Sequence sequence);
  // Starts the threads if they are not running and waits for the first context; "" when
  // every context could be created, otherwise why not.
  std::string start();
  std::string description();  // the renderer, once started
  int peakBusy() const { return peakBusy_.load(); }

 private:
  void worker(int index);
  struct Job {
    Scene scene;
    std::optional<Sequence> sequence;
    std::promise<Result<Frame>> done;
    Stopwatch queued;  // since submit
  };
  PoolOptions options_;
  std::mutex mu_;
  std::condition_variable wake_, ready_;
  std::deque<Job> jobs_;
  std::vector<std::thread> workers_;
  int started_ = 0;  // workers that finished creating their context (or failed)
  std::string startError_, description_;
  bool stopping_ = false;
  std::atomic<int> busy_{0}, peakBusy_{0};
};

}  // namespace effects::render
