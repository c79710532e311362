// The SPIR-V effectd hands out, drawn by Vulkan the way an engine draws a shader it did not write
// (Mesa's lavapipe where there is no GPU): the pipeline from the answer's own SPIR-V words, the
// descriptor bindings and vertex locations from the answer's resource list, the uniform block
// filled by name at the offsets and strides SPIRV-Cross reflects from the shader, the textures the
// answer sends. Each frame is compared with effectd's GL preview (/v1/render) of the same scene
// over the pixels the effect covers: mean and 99th percentile of the largest channel difference.
//   - the bubble, film shading (two sides, two passes each) and paper shading (one blended draw);
//   - fog: quads drawn through the /v1/fog shader's fragment stage (an exponential and a height
//     fog), with a vertex stage written here as an engine writes its own.
// HLSL and MSL are compile-checked only (shader_targets_test.cpp): nothing here runs them.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>

#include <glm/ext/matrix_clip_space.hpp>
#include <glm/ext/matrix_transform.hpp>
#include <glm/geometric.hpp>
#include <glm/gtc/type_ptr.hpp>
#include <glslang/Public/ResourceLimits.h>
#include <glslang/Public/ShaderLang.h>
#include <glslang/SPIRV/GlslangToSpv.h>
#include <render/render.h>
#include <spirv_cross/spirv_cross.hpp>

#include "contract/codec.h"
#include "test_server.h"
#include "vulkan_device.h"

namespace effectd::testing {
namespace {

using nlohmann::json;

std::vector<uint32_t> words(const std::string& base64) {
  const auto bytes = base64Decode(base64);
  EXPECT_TRUE(bytes && bytes->size() % 4 == 0);
  std::vector<uint32_t> w(bytes ? bytes->size() / 4 : 0);
  if (bytes) std::memcpy(w.data(), bytes->data(), w.size() * 4);
  return w;
}

std::vector<uint8_t> decoded(const std::string& base64) {
  const auto bytes = base64Decode(base64);
  EXPECT_TRUE(bytes.has_value());
  return bytes ? std::vector<uint8_t>(bytes->begin(), bytes->end()) : std::vector<uint8_t>{};
}

std::vector<double> numbers(const json& j) {
  std::vector<double> out;
  if (j.is_array())
    for (const auto& x : j) {
      const auto inner = numbers(x);
      out.insert(out.end(), inner.begin(), inner.end());
    }
  else
    out.push_back(j.get<double>());
  return out;
}

// The preview, as 8-bit RGBA rows from the top.
std::vector<uint8_t> preview(const TestServer& s, const json& scene, int& width, int& height) {
  auto r = s.postJson("/v1/render", scene);
  EXPECT_EQ(r->status, 200) << r->body;
  auto image = effects::render::decodeImage(r->body, 1u << 24);
  EXPECT_TRUE(image.ok());
  width = image.value().width, height = image.value().height;
  return effects::render::bytes8(image.value());
}

struct Difference {
  size_t pixels = 0;
  double mean = 0;
  int p99 = 0, worst = 0;
};

// Over the pixels where the preview differs from the backdrop: the largest channel difference.
Difference compare(const std::vector<uint8_t>& expected, const std::vector<uint8_t>& got, const float backdrop[4]) {
  std::vector<int> d;
  for (size_t i = 0; i + 3 < expected.size(); i += 4) {
    int fromBackdrop = 0, diff = 0;
    for (int k = 0; k < 3; ++k) {
      fromBackdrop = std::max(fromBackdrop, std::abs(int(expected[i + k]) - int(std::lround(backdrop[k] * 255))));
      diff = std::max(diff, std::abs(int(expected[i + k]) - int(got[i + k])));
    }
    if (fromBackdrop > 2) d.push_back(diff);
  }
  Difference out;
  out.pixels = d.size();
  if (d.empty()) return out;
  std::sort(d.begin(), d.end());
  double sum = 0;
  for (int x : d) sum += x;
  out.mean = sum / double(d.size());
  out.p99 = d[size_t(0.99 * double(d.size() - 1))];
  out.worst = d.back();
  return out;
}

// Where EFFECTD_VULKAN_PNG_DIR names a folder, the Vulkan frame as a PNG there, to look at.
void keep(const std::vector<uint8_t>& rgba, int w, int h, const std::string& name) {
  const char* dir = std::getenv("EFFECTD_VULKAN_PNG_DIR");
  if (!dir) return;
  effects::render::Image image;
  image.width = w, image.height = h;
  image.rgba8 = rgba;
  auto png = effects::render::encodePng(image, 8);
  if (png.ok()) std::ofstream(std::string(dir) + "/" + name + ".png", std::ios::binary) << png.value();
}

glm::mat4 viewProjection(const glm::vec3& eye, const glm::vec3& target, float fovY, int w, int h) {
  return glm::perspective(glm::radians(fovY), float(w) / float(h), 0.05f, 1000.0f) *
         glm::lookAt(eye, target, glm::vec3(0, 1, 0));
}

// render::skyAt as scene.json documents it, as a cube map (faces +x, -x, +y, -y, +z, -z).
vk::TextureData skyCube(const json& sky, int n) {
  const glm::vec3 zenith(sky["zenith"][0], sky["zenith"][1], sky["zenith"][2]);
  const glm::vec3 horizon(sky["horizon"][0], sky["horizon"][1], sky["horizon"][2]);
  const glm::vec3 ground(sky["ground"][0], sky["ground"][1], sky["ground"][2]);
  vk::TextureData t;
  t.width = t.height = n;
  t.layers = 6;
  t.format = VK_FORMAT_R32G32B32A32_SFLOAT;
  std::vector<float> px;
  for (int face = 0; face < 6; ++face)
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const float s = 2 * (i + 0.5f) / float(n) - 1, u = 2 * (j + 0.5f) / float(n) - 1;
        const glm::vec3 faces[6] = {{1, -u, -s}, {-1, -u, s}, {s, 1, u}, {s, -1, -u}, {s, -u, 1}, {-s, -u, -1}};
        const glm::vec3 d = glm::normalize(faces[face]);
        const glm::vec3 c = d.y >= 0 ? glm::mix(horizon, zenith, std::sqrt(d.y))
                                     : glm::mix(horizon, ground, std::sqrt(std::min(-4 * d.y, 1.0f)));
        px.insert(px.end(), {c.r, c.g, c.b, 1.0f});
      }
  t.bytes.resize(px.size() * 4);
  std::memcpy(t.bytes.data(), px.data(), t.bytes.size());
  return t;
}

std::optional<uint32_t> bindingOf(const json& resources, const std::string& name) {
  for (const auto& r : resources)
    if (r.value("name", "") == name && r.contains("binding")) return r["binding"].get<uint32_t>();
  return std::nullopt;
}

struct Frame {
  std::vector<uint8_t> vulkan, preview;
  int width = 0, height = 0;
  std::string device;
};

// The bubble of `bubble` (a /v1/bubble request) at `time`, under the sky, in Vulkan and in the preview.
Frame drawBubble(const TestServer& s, const json& bubble, bool film, const float backdrop[4], const std::string& name) {
  const int size = 128;
  const double time = 3;
  const glm::vec3 eye(0, 0.3f, 4), target(0);
  const json sky = {{"zenith", {0.35, 0.6, 1.0}}, {"horizon", {1.0, 0.98, 0.95}}, {"ground", {0.16, 0.18, 0.12}}};
  Frame f;
  f.preview = preview(s,
                      {{"width", size}, {"height", size}, {"time", time},
                       {"camera", {{"position", {eye.x, eye.y, eye.z}}, {"target", {0, 0, 0}}, {"fovY", 45}}},
                       {"background", {{"color", {backdrop[0], backdrop[1], backdrop[2], backdrop[3]}}}},
                       {"environment", sky}, {"bubble", bubble}},
                      f.width, f.height);
  json request = bubble;
  request["time"] = time;
  request["thinFilm"] = {{"encoding", "rgba16f"}};
  request["shader"] = {{"language", "spirv"}};
  request["include"] = {"mesh", "uniforms", "shader", "thinFilm"};
  if (film) request["film"] = {{"encoding", "r32f"}}, request["include"].push_back("thickness");
  auto r = s.postJson("/v1/bubble", request);
  EXPECT_EQ(r->status, 200) << r->body;
  const json b = json::parse(r->body);
  const json& shader = b["shader"];
  EXPECT_EQ(shader["language"], "spirv");
  const std::vector<uint32_t> vs = words(shader["vertex"]), fs = words(shader["fragment"]);

  vk::Device device(size, size);
  f.device = device.name();
  // Vertex inputs at the locations the answer lists.
  const json& mesh = b["mesh"];
  std::vector<vk::Attribute> attributes;
  std::vector<vk::Buffer> vertexBuffers;
  for (const auto& res : shader["resources"]) {
    if (res["kind"] != "attribute") continue;
    const std::string a = res["name"];
    const json& data = a == "aPosition" ? mesh["positions"] : a == "aNormal" ? mesh["normals"] : mesh["uvs"];
    vk::Attribute attr{res["location"].get<uint32_t>(), a == "aUv" ? 2u : 3u, data.get<std::vector<float>>()};
    vertexBuffers.push_back(device.buffer(attr.data.data(), attr.data.size() * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT));
    attributes.push_back(std::move(attr));
  }
  const std::vector<uint32_t> indices = mesh["indices"].get<std::vector<uint32_t>>();
  const vk::Buffer indexBuffer = device.buffer(indices.data(), indices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);

  // The textures by the names the shader gives them, at the bindings the answer lists.
  std::map<uint32_t, VkDescriptorType> bindings;
  std::map<uint32_t, const vk::Texture*> textures;
  std::vector<std::unique_ptr<vk::Texture>> owned;
  auto add = [&](const std::string& uniform, const vk::TextureData& data) {
    const auto binding = bindingOf(shader["resources"], uniform);
    if (!binding) return;
    owned.push_back(std::make_unique<vk::Texture>(device.texture(data)));
    textures[*binding] = owned.back().get();
    bindings[*binding] = VK_DESCRIPTOR_TYPE_COMBINED_IMAGE_SAMPLER;
  };
  add("uEnvironment", skyCube(sky, 128));
  vk::TextureData table;
  table.width = b["thinFilm"]["width"], table.height = b["thinFilm"]["height"];
  table.format = VK_FORMAT_R16G16B16A16_SFLOAT;
  table.bytes = decoded(b["thinFilm"]["data"]);
  add("uThinFilm", table);
  if (film) {
    vk::TextureData thickness;
    thickness.width = b["thickness"]["width"], thickness.height = b["thickness"]["height"];
    thickness.format = VK_FORMAT_R32_SFLOAT;
    thickness.bytes = decoded(b["thickness"]["data"]);
    thickness.repeatU = true;
    add("uThicknessField", thickness);
  }

  // The uniform block: the answer's values by name, the camera's, and one copy per uPass.
  const vk::BlockLayout block(vs);
  const auto blockBinding = bindingOf(shader["resources"], "Uniforms");
  EXPECT_TRUE(blockBinding.has_value());
  bindings[*blockBinding] = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  std::vector<uint8_t> data;
  const glm::mat4 identity(1), vp = viewProjection(eye, target, 45, size, size);
  block.fill(data, "uModel", std::vector<double>(glm::value_ptr(identity), glm::value_ptr(identity) + 16));
  block.fill(data, "uViewProjection", std::vector<double>(glm::value_ptr(vp), glm::value_ptr(vp) + 16));
  if (block.has("uCameraPosition")) block.fill(data, "uCameraPosition", {eye.x, eye.y, eye.z});
  for (const auto& [name, value] : b["uniforms"].items()) {
    EXPECT_TRUE(block.has(name)) << name << " is not in the shader's uniform block";
    if (block.has(name)) block.fill(data, name, numbers(value));
  }
  const VkDescriptorSetLayout layout = device.setLayout(bindings);
  std::vector<VkDescriptorSet> sets;
  std::vector<vk::Buffer> uniformBuffers;
  for (int pass = 0; pass < 2; ++pass) {
    if (block.has("uPass")) block.fill(data, "uPass", {double(pass)});
    uniformBuffers.push_back(device.buffer(data.data(), data.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT));
  }
  for (int pass = 0; pass < 2; ++pass) sets.push_back(device.descriptorSet(layout, {{*blockBinding, &uniformBuffers[size_t(pass)]}}, textures));

  // The draws the answer names (shader.draw and shader.blend).
  std::vector<vk::Device::Draw> draws;
  auto draw = [&](const vk::PipelineState& state, int pass) {
    draws.push_back({device.pipeline(vs, fs, attributes, layout, state), layout, sets[size_t(pass)], &vertexBuffers,
                     &indexBuffer, uint32_t(indices.size())});
  };
  if (film) {  // back faces (cull front), then front faces, each transmittance (uPass 0) then reflection (1)
    for (VkCullModeFlags cull : {VK_CULL_MODE_FRONT_BIT, VK_CULL_MODE_BACK_BIT}) {
      draw({cull, true, VK_BLEND_FACTOR_ZERO, VK_BLEND_FACTOR_SRC_COLOR, VK_BLEND_FACTOR_ZERO, VK_BLEND_FACTOR_SRC_ALPHA}, 0);
      draw({cull, true, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE, VK_BLEND_FACTOR_ONE}, 1);
    }
  } else {  // front faces, alpha-blended
    draw({VK_CULL_MODE_BACK_BIT, true, VK_BLEND_FACTOR_SRC_ALPHA, VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA,
          VK_BLEND_FACTOR_SRC_ALPHA, VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA},
         0);
  }
  f.vulkan = device.render(backdrop, draws);
  keep(f.vulkan, size, size, name);
  return f;
}

void expectClose(const Frame& f, const float backdrop[4], double meanTolerance, int p99Tolerance, size_t minPixels,
                 const std::string& what) {
  ASSERT_EQ(f.vulkan.size(), f.preview.size());
  const Difference d = compare(f.preview, f.vulkan, backdrop);
  std::printf("%s on %s: %zu pixels, mean %.3f, p99 %d, worst %d (tolerances %.1f, %d)\n", what.c_str(), f.device.c_str(),
              d.pixels, d.mean, d.p99, d.worst, meanTolerance, p99Tolerance);
  EXPECT_GE(d.pixels, minPixels) << what << ": the effect covers too little of the frame to compare";
  EXPECT_LT(d.mean, meanTolerance) << what;
  EXPECT_LE(d.p99, p99Tolerance) << what;
}

TEST(VulkanDraw, FilmBubbleFromItsSpirvMatchesThePreview) {
  TestServer s;
  const float backdrop[4] = {0.1f, 0.12f, 0.1f, 1};
  const Frame f = drawBubble(s, {{"mesh", {{"level", 4}}}, {"features", {{"wobble", false}}}}, true, backdrop, "bubble-film");
  expectClose(f, backdrop, 0.5, 2, 4000, "film bubble");
}

TEST(VulkanDraw, PaperBubbleFromItsSpirvMatchesThePreview) {
  TestServer s;
  const float backdrop[4] = {0.1f, 0.12f, 0.1f, 1};
  const json bubble = {{"shading", "paper"},
                       {"mesh", {{"level", 4}}},
                       {"features", {{"wobble", false}, {"textureFlow", false}, {"iridescence", true}}}};
  const Frame f = drawBubble(s, bubble, false, backdrop, "bubble-paper");
  expectClose(f, backdrop, 0.5, 2, 2000, "paper bubble");
}

// glslang: an engine's own vertex stage (GLSL 4.50) as SPIR-V.
std::vector<uint32_t> compileVertex(const std::string& source) {
  static const bool initialised = glslang::InitializeProcess();
  (void)initialised;
  glslang::TShader shader(EShLangVertex);
  const char* text = source.c_str();
  shader.setStrings(&text, 1);
  shader.setEnvInput(glslang::EShSourceGlsl, EShLangVertex, glslang::EShClientVulkan, 100);
  shader.setEnvClient(glslang::EShClientVulkan, glslang::EShTargetVulkan_1_0);
  shader.setEnvTarget(glslang::EShTargetSpv, glslang::EShTargetSpv_1_0);
  EXPECT_TRUE(shader.parse(GetDefaultResources(), 450, false, EShMsgDefault)) << shader.getInfoLog();
  glslang::TProgram program;
  program.addShader(&shader);
  EXPECT_TRUE(program.link(EShMsgDefault)) << program.getInfoLog();
  std::vector<uint32_t> spirv;
  glslang::GlslangToSpv(*program.getIntermediate(EShLangVertex), spirv);
  return spirv;
}

// Quads (ground and walls, far to near: drawn in that order they need no depth buffer) fogged by
// the /v1/fog shader's fragment stage, against the preview of the same scene.
void drawFog(const json& fog, const std::string& name) {
  TestServer s;
  const int size = 128;
  const float backdrop[4] = {0, 0, 0, 1};
  const glm::vec3 eye(0, 1.6f, 6), target(0, 1.2f, -20);
  const json quads = {
      {{"center", {0, 0, -45}}, {"normal", {0, 1, 0}}, {"up", {0, 0, -1}}, {"size", {60, 110}}, {"color", {0.35, 0.4, 0.3}}},
      {{"center", {-6, 4, -70}}, {"size", {12, 8}}, {"color", {0.9, 0.3, 0.2}}},
      {{"center", {6, 3, -35}}, {"size", {8, 6}}, {"color", {0.2, 0.5, 0.9}}},
      {{"center", {-3, 1.5, -12}}, {"size", {3, 3}}, {"color", {0.95, 0.9, 0.3}}},
  };
  Frame f;
  f.preview = preview(s,
                      {{"width", size}, {"height", size},
                       {"camera", {{"position", {eye.x, eye.y, eye.z}}, {"target", {target.x, target.y, target.z}}, {"fovY", 50}}},
                       {"background", {{"color", {0, 0, 0, 1}}}}, {"quads", quads}, {"fog", fog}},
                      f.width, f.height);
  json request = fog;
  request["include"] = {"shader"};
  request["shader"] = {{"language", "spirv"}, {"camera", {eye.x, eye.y, eye.z}}};
  auto r = s.postJson("/v1/fog", request);
  ASSERT_EQ(r->status, 200) << r->body;
  const json shader = json::parse(r->body)["shader"];
  const std::vector<uint32_t> fs = words(shader["code"]);

  // The fragment stage's inputs (vWorld, vColor) at the locations it declares.
  spirv_cross::Compiler reflect(fs);
  std::map<std::string, uint32_t> inputs;
  for (const auto& in : reflect.get_shader_resources().stage_inputs)
    inputs[in.name] = reflect.get_decoration(in.id, spv::DecorationLocation);
  ASSERT_TRUE(inputs.count("vWorld") && inputs.count("vColor"));
  const auto fogBinding = bindingOf(shader["resources"], "Uniforms");
  ASSERT_TRUE(fogBinding.has_value());
  const uint32_t cameraBinding = *fogBinding + 1;
  const std::vector<uint32_t> vs = compileVertex(
      "#version 450\nlayout(location = 0) in vec3 aPosition;\nlayout(location = 1) in vec3 aColor;\n"
      "layout(set = 0, binding = " + std::to_string(cameraBinding) + ") uniform Camera { mat4 uViewProjection; };\n"
      "layout(location = " + std::to_string(inputs["vWorld"]) + ") out vec3 vWorld;\n"
      "layout(location = " + std::to_string(inputs["vColor"]) + ") out vec3 vColor;\n"
      "void main() { vWorld = aPosition; vColor = aColor; gl_Position = uViewProjection * vec4(aPosition, 1.0); }\n");

  // The quads' corners as the preview builds them (scene.json: normal faces the viewer, up).
  std::vector<float> position, colour;
  for (const auto& q : quads) {
    const glm::vec3 c(q["center"][0], q["center"][1], q["center"][2]);
    const glm::vec3 n = q.contains("normal") ? glm::normalize(glm::vec3(q["normal"][0], q["normal"][1], q["normal"][2])) : glm::vec3(0, 0, 1);
    glm::vec3 up = q.contains("up") ? glm::vec3(q["up"][0], q["up"][1], q["up"][2]) : glm::vec3(0, 1, 0);
    up = glm::normalize(up - n * glm::dot(up, n)) * (0.5f * float(q["size"][1]));
    const glm::vec3 right = glm::normalize(glm::cross(up, n)) * (0.5f * float(q["size"][0]));
    for (const glm::vec3& p : {c - right - up, c + right - up, c + right + up, c - right - up, c + right + up, c - right + up}) {
      position.insert(position.end(), {p.x, p.y, p.z});
      colour.insert(colour.end(), {float(q["color"][0]), float(q["color"][1]), float(q["color"][2])});
    }
  }
  std::vector<uint32_t> indices(position.size() / 3);
  for (uint32_t i = 0; i < indices.size(); ++i) indices[i] = i;

  vk::Device device(size, size);
  f.device = device.name();
  const std::vector<vk::Attribute> attributes = {{0, 3, position}, {1, 3, colour}};
  const std::vector<vk::Buffer> vertexBuffers = {
      device.buffer(position.data(), position.size() * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT),
      device.buffer(colour.data(), colour.size() * 4, VK_BUFFER_USAGE_VERTEX_BUFFER_BIT)};
  const vk::Buffer indexBuffer = device.buffer(indices.data(), indices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  // The fog's block by the answer's uniforms ({type, values}), the camera's block beside it.
  const vk::BlockLayout block(fs);
  std::vector<uint8_t> fogData;
  for (const auto& [name, u] : shader["uniforms"].items()) {
    EXPECT_TRUE(block.has(name)) << name;
    if (block.has(name)) block.fill(fogData, name, numbers(u["values"]));
  }
  const glm::mat4 vp = viewProjection(eye, target, 50, size, size);
  const vk::Buffer fogBuffer = device.buffer(fogData.data(), fogData.size(), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  const vk::Buffer cameraBuffer = device.buffer(glm::value_ptr(vp), 64, VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  const VkDescriptorSetLayout layout = device.setLayout(
      {{*fogBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}, {cameraBinding, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER}});
  const VkDescriptorSet set = device.descriptorSet(layout, {{*fogBinding, &fogBuffer}, {cameraBinding, &cameraBuffer}}, {});
  const VkPipeline pipeline = device.pipeline(vs, fs, attributes, layout, vk::PipelineState{});
  f.vulkan = device.render(backdrop, {{pipeline, layout, set, &vertexBuffers, &indexBuffer, uint32_t(indices.size())}});
  keep(f.vulkan, size, size, name);
  expectClose(f, backdrop, 0.5, 2, 6000, name);
}

TEST(VulkanDraw, ExponentialFogFromItsSpirvMatchesThePreview) {
  drawFog({{"fog", {{"fogType", "EXPONENTIAL"}, {"color", {0.6, 0.65, 0.7}}, {"visibilityRange", 120}}}}, "fog-exponential");
}

TEST(VulkanDraw, HeightFogFromItsSpirvMatchesThePreview) {
  drawFog({{"fog", {{"fogType", "HEIGHT"}, {"color", {0.7, 0.72, 0.8}}, {"density", 0.08}, {"heightFalloff", 0.35}}}},
          "fog-height");
}

}  // namespace
}  // namespace effectd::testing
