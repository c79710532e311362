// A minimal headless Vulkan 1.1 renderer for tests: what an engine does with a shader it did not
// write. One device and queue, an offscreen RGBA16F colour target (as the GL renderer's frame), buffers and sampled images uploaded
// through a staging buffer, graphics pipelines from SPIR-V words, uniform blocks laid out by
// SPIRV-Cross's reflection of the shader itself, and the frame read back. Errors throw.
#pragma once

#include <vulkan/vulkan.h>

#include <cstdint>
#include <map>
#include <memory>
#include <string>
#include <vector>

namespace effectd::vk {

struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkDeviceSize size = 0;
};

struct Texture {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
  VkSampler sampler = VK_NULL_HANDLE;
};

// What a texture holds: width x height texels of `format`, `layers` faces (6: a cube map, faces
// +x, -x, +y, -y, +z, -z), rows in memory order; repeat or clamp in u.
struct TextureData {
  int width = 0, height = 0, layers = 1;
  VkFormat format = VK_FORMAT_R8G8B8A8_UNORM;
  std::vector<uint8_t> bytes;
  bool repeatU = false;
};

// The fixed-function state of one draw.
struct PipelineState {
  VkCullModeFlags cull = VK_CULL_MODE_NONE;
  bool blend = false;
  VkBlendFactor srcColor = VK_BLEND_FACTOR_ONE, dstColor = VK_BLEND_FACTOR_ZERO;
  VkBlendFactor srcAlpha = VK_BLEND_FACTOR_ONE, dstAlpha = VK_BLEND_FACTOR_ZERO;
};

// One vertex attribute: location, float components, its data (one buffer per attribute).
struct Attribute {
  uint32_t location = 0;
  uint32_t components = 3;
  std::vector<float> data;
};

class Device {
 public:
  // Any Vulkan device (lavapipe on a machine without a GPU); throws if there is none.
  Device(int width, int height);
  ~Device();
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  std::string name() const { return name_; }
  Buffer buffer(const void* data, size_t bytes, VkBufferUsageFlags usage);
  Texture texture(const TextureData& data);

  // A descriptor set layout from (binding -> type) for both stages, a pipeline for it from SPIR-V.
  VkDescriptorSetLayout setLayout(const std::map<uint32_t, VkDescriptorType>& bindings);
  VkPipeline pipeline(const std::vector<uint32_t>& vertexSpirv, const std::vector<uint32_t>& fragmentSpirv,
                      const std::vector<Attribute>& attributes, VkDescriptorSetLayout layout, const PipelineState& state);
  VkDescriptorSet descriptorSet(VkDescriptorSetLayout layout, const std::map<uint32_t, const Buffer*>& uniforms,
                                const std::map<uint32_t, const Texture*>& textures);

  // One frame: clear to `clear`, then each draw (pipeline, set, attributes, indices) in order;
  // returns the frame as RGBA8 rows from the top, round(255 x) as the preview's PNG (the viewport
  // is flipped to GL's y up).
  struct Draw {
    VkPipeline pipeline;
    VkDescriptorSetLayout layout;  // the set layout the pipeline was made with
    VkDescriptorSet set;
    const std::vector<Buffer>* attributes;
    const Buffer* indices;
    uint32_t indexCount;
  };
  std::vector<uint8_t> render(const float clear[4], const std::vector<Draw>& draws);

 private:
  uint32_t memoryType(uint32_t bits, VkMemoryPropertyFlags want) const;
  VkDeviceMemory deviceMemory(VkImage image);  // allocated for and bound to `image`
  VkCommandBuffer begin();
  void submit(VkCommandBuffer cb);
  VkShaderModule module(const std::vector<uint32_t>& words);

  int width_, height_;
  std::string name_;
  VkInstance instance_ = VK_NULL_HANDLE;
  VkPhysicalDevice physical_ = VK_NULL_HANDLE;
  VkDevice device_ = VK_NULL_HANDLE;
  VkQueue queue_ = VK_NULL_HANDLE;
  uint32_t family_ = 0;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkDescriptorPool descriptors_ = VK_NULL_HANDLE;
  VkRenderPass pass_ = VK_NULL_HANDLE;
  Texture target_;
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
  std::vector<Buffer> buffers_;
  std::vector<Texture> textures_;
  std::vector<VkDescriptorSetLayout> layouts_;
  std::vector<VkPipelineLayout> pipelineLayouts_;
  std::map<VkDescriptorSetLayout, VkPipelineLayout> layoutOf_;
  std::vector<VkPipeline> pipelines_;
  std::vector<VkShaderModule> modules_;
};

// A uniform block as the shader declares it (SPIRV-Cross reflection of `spirv`'s block named
// `block`, or its only one): member name -> offset, base type, components, columns, array size and
// strides. fill() writes values (flattened floats; ints written as int32) into `out` by name.
class BlockLayout {
 public:
  BlockLayout(const std::vector<uint32_t>& spirv);
  size_t size() const { return size_; }
  bool has(const std::string& member) const { return members_.count(member) != 0; }
  // Values in declaration order: a matrix column-major, an array element after element.
  void fill(std::vector<uint8_t>& out, const std::string& member, const std::vector<double>& values) const;
  std::vector<std::string> names() const;

 private:
  struct Member {
    uint32_t offset = 0, components = 1, columns = 1, arraySize = 1, arrayStride = 0, matrixStride = 0;
    bool integer = false;
  };
  std::map<std::string, Member> members_;
  size_t size_ = 0;
};

}  // namespace effectd::vk
